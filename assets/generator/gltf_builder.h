// GltfBuilder: assembles a glTF 2.0 model (tinygltf) from meshes, materials, procedural textures, nodes,
// skins, cameras, KHR_lights_punctual lights and animations, and writes it as one .glb.
//
// Reproducibility: every float that goes into the file is first rounded to a multiple of 2^-16 (exact in
// binary, far below anything visible), so a last-bit difference of sin/cos between two C libraries does
// not change the bytes of the output; the test suite regenerates the scenes and compares bytes.
#pragma once

#include <glm/gtc/quaternion.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>
#include <tiny_gltf.h>

#include <cstdint>
#include <string>
#include <vector>

namespace scenegen {

// Rounds to a multiple of 2^-16.
double quantize(double v);

// Triangle mesh data, in the mesh's own space. Optional arrays stay empty.
struct MeshData {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
  std::vector<glm::vec2> texcoords;
  std::vector<std::uint32_t> indices;
  std::vector<glm::u16vec4> joints;     // JOINTS_0
  std::vector<glm::vec4> weights;       // WEIGHTS_0
  std::vector<std::vector<glm::vec3>> morph_positions;  // one displacement array per morph target

  // Appends `other` transformed by `xf` (normals by its inverse transpose).
  void append(const MeshData& other, const glm::mat4& xf = glm::mat4(1.0f));
  // Sets every vertex's skin influence to one joint.
  void bind_all(int joint);
  std::size_t triangles() const { return indices.size() / 3; }
};

struct MaterialDesc {
  std::string name;
  glm::vec4 base_color{1.0f};
  int texture = -1;        // from add_texture
  float metallic = 0.0f;
  float roughness = 0.8f;
  glm::vec3 emissive{0.0f};
  std::string alpha_mode = "OPAQUE";  // OPAQUE, MASK, BLEND
  float alpha_cutoff = 0.5f;
  bool double_sided = false;
};

struct TextureDesc {
  std::string name;
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgba;  // top row first
  bool repeat = true;
  bool nearest_mag = false;
};

struct LightDesc {
  std::string name;
  std::string type = "directional";  // directional, point, spot
  glm::vec3 color{1.0f};
  float intensity = 1.0f;
  float range = 0.0f;
  float inner_cone = 0.0f, outer_cone = 0.785398f;
};

class GltfBuilder {
 public:
  GltfBuilder();

  int add_texture(const TextureDesc& t);
  int add_material(const MaterialDesc& m);
  // A mesh with one primitive. Returns the mesh index.
  int add_mesh(const std::string& name, const MeshData& data, int material, const std::vector<float>& default_weights = {});
  // A node; parent -1 makes it a root of the scene. Returns the node index.
  int add_node(const std::string& name, int parent = -1, const glm::vec3& t = glm::vec3(0.0f),
               const glm::quat& r = glm::quat(1.0f, 0.0f, 0.0f, 0.0f), const glm::vec3& s = glm::vec3(1.0f));
  void set_mesh(int node, int mesh);
  // A skin over `joints` (node indices) with the given inverse bind matrices, used by `node`'s mesh.
  void set_skin(int node, const std::vector<int>& joints, const std::vector<glm::mat4>& inverse_bind, int skeleton);
  void set_camera(int node, const std::string& name, float yfov, float znear, float zfar);
  void set_light(int node, const LightDesc& light);

  // Animation channels of the scene's single clip. `values` hold components per key (tripled, as
  // in-tangent, value, out-tangent, for CUBICSPLINE).
  void animate(int node, const std::string& path, const std::vector<float>& times, const std::vector<float>& values,
               const std::string& interpolation = "LINEAR");
  void set_clip_name(const std::string& name) { clip_name_ = name; }

  // The assembled model (animation and buffer included), as .glb() writes it.
  tinygltf::Model model() const;
  // Serialises to .glb bytes.
  std::vector<unsigned char> glb();

  std::size_t triangle_count() const { return triangles_; }

 private:
  int add_accessor(const void* data, std::size_t bytes, int component_type, std::size_t count, int type,
                   int target, const std::vector<double>& min = {}, const std::vector<double>& max = {});
  int add_floats(std::vector<float> values, int type, int target = 0, bool minmax = false);

  tinygltf::Model model_;
  std::vector<unsigned char> buffer_;
  tinygltf::Animation animation_;
  std::string clip_name_ = "clip";
  std::size_t triangles_ = 0;
};

}  // namespace scenegen
