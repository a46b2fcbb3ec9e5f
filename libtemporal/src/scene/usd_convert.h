// Conversion of a composed USD stage into the format-neutral SceneDescription, shared by usd_load.cpp
// (traversal, transforms, time, cameras, lights), usd_mesh.cpp (UsdGeomMesh), usd_shade.cpp (UsdShade
// materials and UsdUVTexture images) and usd_skel.cpp (UsdSkel skeletons, skinning and blend shapes).
// Internal to src/scene.
#pragma once

#include "scene_description.h"
#include "usd_stage.h"

#include <glm/mat4x4.hpp>

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace temporal::scene_detail::usd_detail {

using usd::Prim;
using usd::PropertySpec;
using usd::Site;
using usd::Value;

// "layer.usda:12:5" of the strongest spec of a prim (or of one property), for messages.
std::string where(const Prim& prim);
std::string where(const Site& site, const PropertySpec& property);

// A UsdSkel Skeleton prim turned into joint nodes.
struct Skeleton {
  std::string path;
  std::vector<std::string> joints;       // joint paths ("hip/knee")
  std::vector<int> joint_nodes;          // node of each joint
  std::vector<glm::mat4> bind;           // bindTransforms: joint to skeleton space at bind time
  std::vector<std::string> blend_shapes;  // the bound SkelAnimation's blendShapes
  int blend_weight_sampler = -1;          // its blendShapeWeights (one component per blend shape), or -1
  std::vector<float> blend_weight_rest;   // blendShapeWeights default (or first sample)
};

// A Mesh prim found by the traversal, converted once materials and skeletons are known.
struct MeshJob {
  const Prim* prim = nullptr;
  int node = -1;
  std::vector<std::string> material_keys;  // slot 0: the mesh's material; slot k: GeomSubset k's
  std::vector<std::vector<int>> slot_faces;  // faces of slots 1.. (from GeomSubset indices)
};

// What a SceneMaterial is made from: a Material prim (or none), the sidedness of the meshes that use it and
// the display colour of the mesh when the material reads it (or when there is no material).
struct MaterialRecipe {
  std::string material;  // Material prim path, "" for none
  bool double_sided = false;
  bool has_color = false;
  glm::vec3 display_color{0.0f};
};

struct Converter {
  Converter(const usd::Stage& s, SceneDescription& o) : stage(s), out(o) {}
  const usd::Stage& stage;
  SceneDescription& out;
  double start_tc = 0.0;    // stage startTimeCode
  double tcps = 24.0;       // timeCodesPerSecond
  bool sampled = false;     // something is time-sampled
  double last_tc = 0.0;     // the largest sampled stage time code
  std::vector<MeshJob> meshes;
  std::vector<std::string> material_prims;         // Material prims in traversal order
  std::map<std::string, MaterialRecipe> recipes;   // material key -> recipe
  std::vector<std::string> key_order;              // material keys in order of first use
  std::map<std::string, int> material_index;       // material key -> SceneMaterial index
  std::vector<std::string> uv_primvar;             // per SceneMaterial: the primvar its texture reads ("st")
  std::map<std::string, int> texture_index;        // texture key -> SceneTexture index
  std::map<std::string, Skeleton> skeletons;       // by Skeleton prim path
  std::vector<std::string> warned;                 // warnings given once

  void warn(const std::string& message);
  void warn_once(const std::string& key, const std::string& message);

  // ---- values -------------------------------------------------------------------------------------------
  // The value of an attribute at the stage's start: its default, else its first time sample; nullptr when
  // unauthored or blocked.
  const Value* value(const Prim& prim, std::string_view name) const;
  std::optional<double> number(const Prim& prim, std::string_view name) const;
  std::optional<std::string> token(const Prim& prim, std::string_view name) const;
  // Numbers of an attribute with `tuple` numbers per element (nullptr when unauthored or another shape); they
  // live as long as the stage.
  const std::vector<double>* numbers(const Prim& prim, std::string_view name, int tuple) const;
  // The same with `fallback` when absent.
  std::vector<double> numbers_or(const Prim& prim, std::string_view name, int tuple, std::vector<double> fallback) const;
  // A sampler over the attribute's time samples (seconds), each sample holding `components` floats after
  // `convert` (which may reorder, e.g. quaternions from USD's w, x, y, z to x, y, z, w). -1 when the attribute
  // has fewer than two time samples. Samples of another size are an error naming the sample.
  Expected<int> sampler(const Prim& prim, std::string_view name, int components, Interpolation interpolation,
                        void (*convert)(const double* in, float* out, int components) = nullptr);
  float seconds(const Site& site, double layer_time_code) const;

  // ---- traversal (usd_load.cpp) --------------------------------------------------------------------------
  Status traverse(const Prim& prim, int parent_node, int depth, bool drawn);
  Expected<int> transform_node(const Prim& prim, int parent_node, bool force);
  int add_node(const std::string& name, int parent);
  Status camera(const Prim& prim, int node);
  Status light(const Prim& prim, int node);
  Status finish_time();

  // ---- meshes (usd_mesh.cpp) -----------------------------------------------------------------------------
  Status mesh(const MeshJob& job);
  void emit_primitives(const MeshJob& job, ScenePrimitive& full, PrimitiveData& data,
                       std::vector<std::vector<std::uint32_t>>& slot_tris);

  // ---- materials (usd_shade.cpp) -------------------------------------------------------------------------
  // The material key of a mesh (or of one of its GeomSubsets, `gprim`): bound Material, display colour,
  // sidedness. Materials are created once every key is known (create_materials), so that SceneMaterial
  // indices follow the order of the Material prims.
  std::string material_key(const Prim& gprim, const Prim& mesh, bool double_sided, const double* color = nullptr);
  bool color_slots(MeshJob& job, bool double_sided);
  Status material_slots(MeshJob& job);
  Status create_materials();
  Status preview_surface(const Prim& material, const MaterialRecipe& recipe, SceneMaterial& m, std::string& uv);
  Status uv_texture(const Prim& texture, SceneMaterial& m, std::string& uv);

  // ---- UsdSkel (usd_skel.cpp) ----------------------------------------------------------------------------
  Status skeleton(const Prim& prim, int node);
  // A sampler holding components [first, first + count) of sampler `whole` (one joint of an array sample).
  int slice(int whole, int first, int count);
  // Skinning and blend shapes of a mesh (under a SkelRoot, bound to a converted Skeleton); per-point data
  // reaches the primitive's vertices through data.vertex_point.
  Status bind_skin(const Prim& mesh, int node, std::size_t point_count, ScenePrimitive& prim, PrimitiveData& data);
  Status blend_shapes(const Prim& mesh, int node, const Skeleton& skeleton, const std::vector<std::string>& shapes,
                      std::size_t point_count, ScenePrimitive& prim, PrimitiveData& data);
};

}  // namespace temporal::scene_detail::usd_detail
