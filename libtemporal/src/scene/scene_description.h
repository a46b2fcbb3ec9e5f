// The format-neutral scene description that every reader fills (gltf_*.cpp for glTF 2.0, usd_*.cpp for
// text USD) and that Scene::evaluate() replays, in the spirit of pbrt-v4's BasicScene: readers translate
// their format into nodes with a transform source that can be evaluated at any time, triangle meshes with
// per-vertex skinning and morph data, materials, textures, cameras and lights; nothing downstream (the
// evaluation, the renderer, motion vectors) knows which format a scene came from. Internal to src/scene.
//
// Conventions: column vectors (glm), world space Y up, lengths in the file's units, times in seconds from
// the start of the clip (glTF) or of the stage's timeline (USD: (timeCode - startTimeCode) / timeCodesPerSecond).
#pragma once

#include "temporal/scene/scene.h"

#include <glm/gtc/quaternion.hpp>
#include <glm/mat4x4.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace temporal::scene_detail {

// Rotation quaternions shorter than this (in double) are refused on load: a zero quaternion has no rotation to
// normalise to (docs/scenes.md).
inline constexpr double kMinRotationLength = 1e-6;

// Texture coordinates beyond +-kMaxTexcoord are refused on load: 3e38 is finite but overflows the texture
// lookup (coordinate x texture size) into NaN pixels, and past 1e6 float has no sub-texel precision anyway.
inline constexpr float kMaxTexcoord = 1e6f;
inline bool texcoord_in_range(const glm::vec2& uv) { return std::abs(uv.x) <= kMaxTexcoord && std::abs(uv.y) <= kMaxTexcoord; }

enum class TargetPath { Translation, Rotation, Scale, Weights };
enum class Interpolation { Step, Linear, CubicSpline };

// Keyframes of one animated value, converted to float. glTF samplers and USD time samples both become one.
struct Sampler {
  std::vector<float> times;   // seconds, increasing (validated by the readers)
  std::vector<float> values;  // count * components, or 3 * count * components for CUBICSPLINE
  int components = 0;         // 3 (T, S), 4 (R as x, y, z, w), morph target count (weights), 16 (matrices), ...
  Interpolation interpolation = Interpolation::Linear;
};

// Writes the sampler's value at time t (seconds) into out[0 .. components). Times before the first key
// give the first value, after the last key the last value (glTF 2.0 section 3.11; USD holds the end values
// the same way). `rotation`: the value is a quaternion (x, y, z, w), slerped along the shortest arc (LINEAR,
// as glTF Appendix C and USD's GfSlerp) and normalised.
void sample(const Sampler& sampler, float t, bool rotation, float* out);

// A sampler driving one TRS component or the morph weights of a node.
struct Channel {
  int node = -1;
  TargetPath path = TargetPath::Translation;
  int sampler = -1;
};

// One operation of a USD transform stack (UsdGeomXformOp). Values are in the op's own units: translate and
// scale (x, y, z), rotateX/Y/Z (degrees), rotateXYZ and the other orders (degrees about x, y, z; rotateXYZ
// turns about X first), orient (quaternion x, y, z, w), transform (16 values, column-major for glm).
struct XformOp {
  enum class Kind : std::uint8_t {
    Translate, Scale, RotateX, RotateY, RotateZ, RotateXYZ, RotateXZY, RotateYXZ, RotateYZX, RotateZXY, RotateZYX,
    Orient, Transform
  };
  Kind kind = Kind::Translate;
  bool inverse = false;           // "!invert!" ops apply the inverse
  std::array<float, 16> value{};  // constant value (the first 1, 3, 4 or 16 entries)
  int sampler = -1;               // time-sampled value in the same layout, else the constant
};

// A node of the transform hierarchy. Its local transform is, in this order of precedence: the product of
// `ops` (USD stacks other than translate/orient/scale), `matrix` (glTF matrix, a constant USD transform), or
// T * R * S from translation, rotation, scale and the channels that animate them.
struct Node {
  std::string name;
  int parent = -1;
  glm::vec3 translation{0.0f};
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};
  glm::vec3 scale{1.0f};
  glm::mat4 matrix{1.0f};
  bool use_matrix = false;
  std::vector<XformOp> ops;   // non-empty: local = ops[0] * ops[1] * ... (the last op acts first)
  bool reset_parent = false;  // USD "!resetXformStack!": the node's world transform ignores its ancestors
  int skin = -1;              // skin of the primitives this node draws
  int weight_offset = -1;     // into the per-evaluation weight array (nodes drawing a morphed mesh)
  int weight_count = 0;
  std::vector<float> rest_weights;
};

struct Skin {
  std::vector<int> joints;              // node indices
  std::vector<glm::mat4> inverse_bind;  // one per joint: mesh space to joint space at bind time
  // How normals are skinned. glTF (false): by the inverse transpose of the weight-blended joint matrix
  // (section 3.7.3.2). UsdSkel (true): by the weight-blended inverse transposes of the joint matrices, as
  // OpenUSD's UsdSkelSkinNormalsLBS does. The two differ where a vertex blends joints that turn apart.
  bool blend_normal_matrices = false;
};

// Per-primitive data that ScenePrimitive does not carry: skin influences, morph deltas, point caches.
struct PrimitiveData {
  int influences = 0;                       // joints per vertex
  std::vector<std::uint16_t> joints;        // vertex_count * influences (indices into the node's skin)
  std::vector<float> weights;               // vertex_count * influences, normalised to sum 1
  std::vector<std::vector<glm::vec3>> target_positions;  // per morph target, per vertex (deltas)
  std::vector<std::vector<glm::vec3>> target_normals;    // empty vectors where the target has none
  bool flat_normals = false;                // normals were generated flat: recompute them after deforming
  bool smooth_normals = false;              // normals were generated smooth (USD mesh without normals):
                                            // recomputed from the deformed triangles
  // Time-sampled positions / normals (USD points.timeSamples): samplers over every point (3 floats each);
  // vertex v reads point vertex_point[v] (identity when empty). They replace the rest values.
  int point_sampler = -1;
  int normal_sampler = -1;
  std::vector<std::uint32_t> vertex_point;
  std::vector<std::uint32_t> vertex_normal;  // vertex -> element of normal_sampler (faceVarying normals);
                                             // empty: the vertex's point
  glm::vec3 local_min{0.0f}, local_max{0.0f};
};

// One node drawing one primitive.
struct Draw {
  int node = -1;
  int primitive = -1;
};

struct CameraDef {
  std::string name;               // glTF: name (or index); USD: prim name
  std::string path;               // USD prim path (also accepted by CameraOptions::camera); empty for glTF
  bool orthographic = false;
  float yfov = 0.8f, aspect = 0.0f, znear = 0.1f, zfar = 0.0f;  // zfar 0: infinite
  // USD cameras whose lens or clipping range are time-sampled: yfov = 2 atan(verticalAperture / (2 focalLength)).
  int focal_sampler = -1, aperture_sampler = -1, clipping_sampler = -1;
  float focal_length = 50.0f, vertical_aperture = 15.2908f;
};

// A camera placed by a node (looks down the node's -Z).
struct CameraInstance {
  int camera = -1;  // index into cameras
  int node = -1;
};

struct LightDef {
  LightState light;  // position/direction filled per evaluation from the node
  int node = -1;
};

// What a reader produces. `order` lists every node with each parent before its children; draws,
// camera instances and lights appear in that order, which fixes the instance order of every evaluation.
struct SceneDescription {
  std::string file;
  std::vector<std::string> inputs;  // every file the reader read: the scene, buffers, images, layers, textures
  std::string format;  // "glTF 2.0" or "USD"
  std::vector<ScenePrimitive> primitives;
  std::vector<SceneMaterial> materials;
  std::vector<SceneTexture> textures;
  std::vector<Node> nodes;
  std::vector<int> order;
  std::vector<Skin> skins;
  std::vector<PrimitiveData> primitive_data;  // parallel to primitives
  std::vector<Draw> draws;
  int weight_total = 0;

  std::vector<Sampler> samplers;  // of the selected clip(s) / the USD timeline
  std::vector<Channel> channels;
  std::vector<std::string> clip_names;
  double clip_duration = 0.0;     // seconds; 0: static. Evaluation time wraps at it.

  std::vector<CameraDef> cameras;               // every camera definition (names for --camera)
  std::vector<CameraInstance> camera_instances;  // cameras placed in the drawn scene, in node order
  std::vector<LightDef> lights;                  // light instances in the drawn scene, in node order
  glm::vec3 ambient{0.0f};                       // radiance of a uniform environment (USD DomeLight)

  std::vector<std::string> warnings;
};

// Evaluation state derived from the description once all of it is known (scene_finish.cpp).
struct Impl : SceneDescription {
  glm::vec3 bounds_min{0.0f}, bounds_max{0.0f};
  int camera_instance = -1;  // -1: automatic camera
  CameraDef camera;          // the selected camera (zfar resolved)
  CameraOptions::Path path = CameraOptions::Path::Fixed;
  double path_period_s = 8.0;
  glm::vec3 auto_center{0.0f};
  glm::vec3 auto_direction{0.0f, 0.0f, 1.0f};  // from the centre towards the camera at t = 0
  float auto_distance = 1.0f;
  LightState key_light;  // used when `lights` is empty
};

// "'name'" or "#index" for messages.
std::string quoted_or_index(const std::string& name, std::size_t index);
// A decimal index of at most 9 digits (a longer number cannot be an index, and would overflow std::stoul): a clip
// or camera named so is looked up by index, else by name (and refused as unknown).
bool is_index(const std::string& s);
// "a, b, c" ("none" when empty), for the messages that list what a scene has.
std::string join_names(const std::vector<std::string>& names);

}  // namespace temporal::scene_detail

namespace temporal {
// The pimpl of Scene is the plain struct above (kept in a namespace so that tests and every reader see it).
struct Scene::Impl : scene_detail::Impl {};
}  // namespace temporal
