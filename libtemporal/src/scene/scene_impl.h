// Internal state of temporal::Scene: the node graph, skins, morph data and animation samplers that
// Scene::evaluate() replays. Not a public header (src/scene only).
#pragma once

#include "temporal/scene/scene.h"

#include <glm/gtc/quaternion.hpp>
#include <glm/mat4x4.hpp>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace temporal::scene_detail {

enum class TargetPath { Translation, Rotation, Scale, Weights };
enum class Interpolation { Step, Linear, CubicSpline };

// One glTF animation sampler, keyframe data converted to float (normalised integers decoded).
struct Sampler {
  std::vector<float> times;   // strictly increasing after load (validated)
  std::vector<float> values;  // count * components, or 3 * count * components for CUBICSPLINE
  int components = 0;         // 3 (T, S), 4 (R), morph target count (weights)
  Interpolation interpolation = Interpolation::Linear;
};

// Writes the sampler's value at time t (seconds) into out[0 .. components). Times before the first key
// give the first value, after the last key the last value (glTF 2.0, section 3.11). Rotations are
// slerped along the shortest arc (LINEAR) and normalised (all modes).
void sample(const Sampler& sampler, float t, bool rotation, float* out);

struct Channel {
  int node = -1;
  TargetPath path = TargetPath::Translation;
  int sampler = -1;
};

struct Node {
  std::string name;
  int parent = -1;
  glm::vec3 translation{0.0f};
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};
  glm::vec3 scale{1.0f};
  glm::mat4 matrix{1.0f};
  bool use_matrix = false;   // the node gave `matrix` (it can then not be animated, spec 3.5.3)
  int mesh = -1, skin = -1, camera = -1, light = -1;
  int weight_offset = -1;    // into the per-evaluation weight array (nodes with a morphed mesh)
  int weight_count = 0;
  std::vector<float> rest_weights;  // node.weights, else mesh.weights, else zeros
};

struct Skin {
  std::vector<int> joints;              // node indices
  std::vector<glm::mat4> inverse_bind;  // one per joint (identity when the file has none)
};

// Per-primitive data that ScenePrimitive does not carry: skin influences and morph deltas.
struct PrimitiveData {
  int influences = 0;                       // joints per vertex: 4 per JOINTS_n/WEIGHTS_n set
  std::vector<std::uint16_t> joints;        // vertex_count * influences
  std::vector<float> weights;               // vertex_count * influences, normalised to sum 1
  std::vector<std::vector<glm::vec3>> target_positions;  // per morph target, per vertex (deltas)
  std::vector<std::vector<glm::vec3>> target_normals;    // empty vectors where the target has none
  bool flat_normals = false;                // normals were generated: recompute them after deforming
  glm::vec3 local_min{0.0f}, local_max{0.0f};
};

// One node drawing one primitive.
struct Draw {
  int node = -1;
  int primitive = -1;
};

struct CameraDef {
  std::string name;
  bool orthographic = false;
  float yfov = 0.8f, aspect = 0.0f, znear = 0.1f, zfar = 0.0f;  // zfar 0: infinite in the file
};

struct LightDef {
  LightState light;  // position/direction filled per evaluation from the node
  int node = -1;
};

struct Impl {
  std::string file;
  std::vector<Node> nodes;
  std::vector<int> order;  // the selected scene's nodes, every parent before its children
  std::vector<Skin> skins;
  std::vector<PrimitiveData> primitive_data;  // parallel to Scene::primitives()
  std::vector<Draw> draws;
  int weight_total = 0;

  std::vector<Sampler> samplers;  // of the selected clip(s)
  std::vector<Channel> channels;
  std::vector<std::string> clip_names;

  std::vector<CameraDef> cameras;  // glTF cameras
  std::vector<LightDef> lights;    // light instances in the scene (one per node referencing a light)
  LightState key_light;            // used when `lights` is empty

  // Camera: a glTF camera through its node, or the automatic one.
  int camera_node = -1;  // -1: automatic
  CameraDef camera;      // the selected glTF camera (zfar resolved)
  CameraOptions::Path path = CameraOptions::Path::Fixed;
  double path_period_s = 8.0;
  glm::vec3 auto_center{0.0f};
  glm::vec3 auto_direction{0.0f, 0.0f, 1.0f};  // from the centre towards the camera at t = 0
  float auto_distance = 1.0f;

  std::vector<std::string> warnings;
};

}  // namespace temporal::scene_detail

namespace temporal {
// The pimpl of Scene is the plain struct above (kept in a namespace so that tests and both .cpp files see it).
struct Scene::Impl : scene_detail::Impl {};
}  // namespace temporal
