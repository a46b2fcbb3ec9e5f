// Scene loading and evaluation against hand-written glTF files whose expected values are computed by hand
// (glTF 2.0 sections 3.5 node transforms, 3.7 meshes / skins / morph targets, 3.11 and Appendix C
// animation samplers).
#include "gltf_writer.h"
#include "test_support.h"

#include "temporal/scene/scene.h"

#include <glm/gtc/matrix_transform.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

namespace temporal {
namespace {

using test::GltfBuffer;
using test::write_gltf;

constexpr float kEps = 1e-5f;

// A unit right triangle in the XY plane, facing +Z, as the mesh every test scene draws.
struct Triangle {
  int position, normal, indices;
};
Triangle add_triangle(GltfBuffer& b) {
  return {b.add_floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3"), b.add_floats({0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3"),
          b.add_ushorts({0, 1, 2}, "SCALAR")};
}
std::string triangle_mesh(const Triangle& t) {
  return "\"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": " + std::to_string(t.position) +
         ", \"NORMAL\": " + std::to_string(t.normal) + "}, \"indices\": " + std::to_string(t.indices) + "}]}],\n";
}

glm::vec3 origin(const glm::mat4& m) { return glm::vec3(m[3]); }

void expect_vec3(const glm::vec3& actual, const glm::vec3& expected, float tol, const std::string& what) {
  EXPECT_NEAR(actual.x, expected.x, tol) << what;
  EXPECT_NEAR(actual.y, expected.y, tol) << what;
  EXPECT_NEAR(actual.z, expected.z, tol) << what;
}

// Model matrix of the instance drawn by `node`.
glm::mat4 model_of(const FrameState& f, int node) {
  for (const auto& inst : f.instances) {
    if (inst.node == node) return inst.model;
  }
  ADD_FAILURE() << "no instance for node " << node;
  return glm::mat4(1.0f);
}

std::string animation_scene(const std::filesystem::path& dir) {
  GltfBuffer b;
  const Triangle tri = add_triangle(b);
  const int t012 = b.add_floats({0, 1, 2}, "SCALAR");
  const int t02 = b.add_floats({0, 2}, "SCALAR");
  const int t01 = b.add_floats({0, 1}, "SCALAR");
  const int step = b.add_floats({0, 0, 0, 1, 0, 0, 2, 0, 0}, "VEC3");
  const int linear = b.add_floats({0, 0, 0, 4, 2, 0}, "VEC3");
  // CUBICSPLINE: per key (in-tangent, value, out-tangent).
  const int cubic = b.add_floats({0, 0, 0, /**/ 0, 0, 0, /**/ 1, 0, 0,  //
                                  0, 3, 0, /**/ 1, 0, 0, /**/ 0, 0, 0},
                                 "VEC3");
  const float s45 = std::sqrt(0.5f);
  const int rot = b.add_floats({0, 0, 0, 1, 0, s45, 0, s45}, "VEC4");
  const int rot_neg = b.add_floats({0, 0, 0, 1, 0, -s45, 0, -s45}, "VEC4");  // same rotation, other hemisphere
  const std::string body = triangle_mesh(tri) + R"(
"nodes": [{"mesh": 0, "name": "step"}, {"mesh": 0, "name": "linear"}, {"mesh": 0, "name": "cubic"},
          {"mesh": 0, "name": "slerp"}, {"mesh": 0, "name": "slerp_neg"}],
"scenes": [{"nodes": [0, 1, 2, 3, 4]}],
"animations": [{"name": "samplers", "channels": [
  {"sampler": 0, "target": {"node": 0, "path": "translation"}},
  {"sampler": 1, "target": {"node": 1, "path": "translation"}},
  {"sampler": 2, "target": {"node": 2, "path": "translation"}},
  {"sampler": 3, "target": {"node": 3, "path": "rotation"}},
  {"sampler": 4, "target": {"node": 4, "path": "rotation"}}],
 "samplers": [
  {"input": )" + std::to_string(t012) + R"(, "output": )" + std::to_string(step) + R"(, "interpolation": "STEP"},
  {"input": )" + std::to_string(t02) + R"(, "output": )" + std::to_string(linear) + R"(},
  {"input": )" + std::to_string(t02) + R"(, "output": )" + std::to_string(cubic) + R"(, "interpolation": "CUBICSPLINE"},
  {"input": )" + std::to_string(t01) + R"(, "output": )" + std::to_string(rot) + R"(, "interpolation": "LINEAR"},
  {"input": )" + std::to_string(t01) + R"(, "output": )" + std::to_string(rot_neg) + R"(, "interpolation": "LINEAR"}]}])";
  return write_gltf(dir, "animation", b, body);
}

TEST(SceneAnimation, StepLinearCubicSplineAndSlerpMatchHandValues) {
  const auto path = animation_scene(test::scratch_dir("scene_animation"));
  auto scene = Scene::load(path);
  ASSERT_TRUE(scene) << scene.error().message;
  EXPECT_DOUBLE_EQ(scene->clip_duration(), 2.0);
  ASSERT_EQ(scene->clip_names().size(), 1u);
  EXPECT_EQ(scene->clip_names()[0], "samplers");

  // STEP holds the previous key: keys (0,0,0) @0, (1,0,0) @1, (2,0,0) @2.
  expect_vec3(origin(model_of(scene->evaluate(0.5), 0)), {0, 0, 0}, kEps, "step t=0.5");
  expect_vec3(origin(model_of(scene->evaluate(1.0), 0)), {1, 0, 0}, kEps, "step t=1");
  expect_vec3(origin(model_of(scene->evaluate(1.99), 0)), {1, 0, 0}, kEps, "step t=1.99");
  // LINEAR between (0,0,0) @0 and (4,2,0) @2.
  expect_vec3(origin(model_of(scene->evaluate(0.5), 1)), {1, 0.5f, 0}, kEps, "linear t=0.5");
  expect_vec3(origin(model_of(scene->evaluate(1.5), 1)), {3, 1.5f, 0}, kEps, "linear t=1.5");
  // CUBICSPLINE, td = 2: p(s) = h00 v0 + h10 td b0 + h01 v1 + h11 td a1 with v0 = 0, b0 = (1,0,0),
  // v1 = (1,0,0), a1 = (0,3,0). s = 0.5: h10 = 0.125, h01 = 0.5, h11 = -0.125 -> x = 0.75, y = -0.75.
  expect_vec3(origin(model_of(scene->evaluate(1.0), 2)), {0.75f, -0.75f, 0}, kEps, "cubic t=1");
  // s = 0.25: h10 = 0.140625, h01 = 0.15625, h11 = -0.046875 -> x = 0.4375, y = -0.28125.
  expect_vec3(origin(model_of(scene->evaluate(0.5), 2)), {0.4375f, -0.28125f, 0}, kEps, "cubic t=0.5");
  // Slerp from identity to 90 degrees about +Y, halfway: 45 degrees; the X axis maps to (cos45, 0, -sin45).
  const float c45 = std::sqrt(0.5f);
  for (int node : {3, 4}) {
    const glm::mat4 m = model_of(scene->evaluate(0.5), node);
    expect_vec3(glm::vec3(m[0]), {c45, 0, -c45}, 1e-5f, "slerp x axis, node " + std::to_string(node));
    expect_vec3(glm::vec3(m[1]), {0, 1, 0}, 1e-5f, "slerp y axis, node " + std::to_string(node));
  }
  // At 1/4 of the way: 22.5 degrees (slerp has constant angular speed; a plain lerp would give 24.1).
  const glm::mat4 m = model_of(scene->evaluate(0.25), 3);
  EXPECT_NEAR(std::atan2(-m[0][2], m[0][0]), glm::radians(22.5f), 1e-5f);
  // Time wraps at the clip's end (2 s).
  expect_vec3(origin(model_of(scene->evaluate(2.5), 1)), {1, 0.5f, 0}, kEps, "linear t=2.5 (wrapped)");
}

TEST(SceneHierarchy, NodeTransformsComposeParentFirst) {
  GltfBuffer b;
  const Triangle tri = add_triangle(b);
  const float s45 = std::sqrt(0.5f);
  const std::string body = triangle_mesh(tri) + R"(
"nodes": [
 {"name": "A", "translation": [1, 0, 0], "rotation": [0, )" + std::to_string(s45) + ", 0, " + std::to_string(s45) + R"(], "children": [1]},
 {"name": "B", "translation": [0, 0, 2], "scale": [2, 2, 2], "children": [2], "mesh": 0},
 {"name": "C", "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,1,0,1], "mesh": 0}],
"scenes": [{"nodes": [0]}])";
  auto scene = Scene::load(write_gltf(test::scratch_dir("scene_hierarchy"), "hierarchy", b, body));
  ASSERT_TRUE(scene) << scene.error().message;
  const FrameState f = scene->evaluate(0.0);
  ASSERT_EQ(f.instances.size(), 2u);
  // B = A * T(0,0,2) S(2): origin R_y(90)(0,0,2) + (1,0,0) = (3,0,0); its X axis 2 * R_y(90) x = (0,0,-2).
  const glm::mat4 mb = model_of(f, 1);
  expect_vec3(origin(mb), {3, 0, 0}, kEps, "B origin");
  expect_vec3(glm::vec3(mb[0]), {0, 0, -2}, kEps, "B x axis");
  // C = A * B * T(0,1,0): B maps (0,1,0) to (0,2,0) + (0,0,2), A then to R_y(90)(0,2,2) + (1,0,0) = (3,2,0).
  expect_vec3(origin(model_of(f, 2)), {3, 2, 0}, kEps, "C origin");
  EXPECT_FALSE(f.instances[0].deformed);
  EXPECT_TRUE(f.instances[0].world_positions.empty()) << "rigid primitives carry only a model matrix";
  // Bounds: B's triangle (0,0,0),(1,0,0),(0,1,0) -> (3,0,0),(3,0,-2),(3,2,0); C's -> (3,2,0),(3,2,-2),(3,4,0).
  expect_vec3(scene->bounds_min(), {3, 0, -2}, kEps, "bounds min");
  expect_vec3(scene->bounds_max(), {3, 4, 0}, kEps, "bounds max");
}

std::string skin_scene(const std::filesystem::path& dir) {
  GltfBuffer b;
  const int pos = b.add_floats({0, 0, 0, 1, 0, 0, 0, 2, 0, 1, 1, 0}, "VEC3");
  const int nrm = b.add_floats({0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3");
  const int idx = b.add_ushorts({0, 1, 2, 1, 3, 2}, "SCALAR");
  const int joints = b.add_ushorts({0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0}, "VEC4");
  const int weights = b.add_floats({1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0.5f, 0.5f, 0, 0}, "VEC4");
  // Inverse bind matrices: joint 0 rests at the origin, joint 1 at (0,1,0).
  const int ibm = b.add_floats({1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1,  //
                                1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -1, 0, 1},
                               "MAT4");
  const int times = b.add_floats({0, 1, 2}, "SCALAR");
  const float s45 = std::sqrt(0.5f);
  const int rot = b.add_floats({0, 0, 0, 1, 0, 0, s45, s45, 0, 0, s45, s45}, "VEC4");
  const std::string body = R"("meshes": [{"primitives": [{"attributes": {"POSITION": )" + std::to_string(pos) +
                           R"(, "NORMAL": )" + std::to_string(nrm) + R"(, "JOINTS_0": )" + std::to_string(joints) +
                           R"(, "WEIGHTS_0": )" + std::to_string(weights) + R"(}, "indices": )" + std::to_string(idx) + R"(}]}],
"nodes": [{"name": "skinned", "mesh": 0, "skin": 0, "translation": [5, 0, 0]},
          {"name": "j0", "children": [2]}, {"name": "j1", "translation": [0, 1, 0]}],
"skins": [{"joints": [1, 2], "inverseBindMatrices": )" + std::to_string(ibm) + R"(}],
"scenes": [{"nodes": [0, 1]}],
"animations": [{"channels": [{"sampler": 0, "target": {"node": 2, "path": "rotation"}}],
  "samplers": [{"input": )" + std::to_string(times) + R"(, "output": )" + std::to_string(rot) + R"(}]}])";
  return write_gltf(dir, "skin", b, body);
}

TEST(SceneSkinning, LinearBlendSkinningMatchesHandValues) {
  auto scene = Scene::load(skin_scene(test::scratch_dir("scene_skin")));
  ASSERT_TRUE(scene) << scene.error().message;
  ASSERT_EQ(scene->primitives().size(), 1u);
  EXPECT_TRUE(scene->primitives()[0].skinned);
  // t = 0: bind pose; the skinned node's own translation (5,0,0) is ignored (glTF 2.0 section 3.7.3).
  FrameState f = scene->evaluate(0.0);
  ASSERT_TRUE(f.instances[0].deformed);
  const auto& rest = scene->primitives()[0].positions;
  for (std::size_t v = 0; v < rest.size(); ++v) expect_vec3(f.instances[0].world_positions[v], rest[v], kEps, "bind pose");
  // t = 1: joint 1 turned 90 degrees about Z around (0,1,0).
  // v2 = (0,2,0), only joint 1: (0,1,0) relative -> (-1,0,0) -> (-1,1,0).
  // v3 = (1,1,0), half each: joint 0 keeps (1,1,0); joint 1: (1,0,0) -> (0,1,0) -> (0,2,0); mean (0.5,1.5,0).
  f = scene->evaluate(1.0);
  const auto& p = f.instances[0].world_positions;
  expect_vec3(p[0], {0, 0, 0}, kEps, "v0");
  expect_vec3(p[1], {1, 0, 0}, kEps, "v1");
  expect_vec3(p[2], {-1, 1, 0}, kEps, "v2");
  expect_vec3(p[3], {0.5f, 1.5f, 0}, kEps, "v3");
  for (const auto& n : f.instances[0].world_normals) expect_vec3(n, {0, 0, 1}, kEps, "normal");
  // t = 0.5: 45 degrees: v2 = (-sin45, 1 + cos45, 0).
  f = scene->evaluate(0.5);
  const float s45 = std::sqrt(0.5f);
  expect_vec3(f.instances[0].world_positions[2], {-s45, 1 + s45, 0}, kEps, "v2 at 45 degrees");
}

TEST(SceneMorph, TargetWeightsFromAnimationNodeAndMesh) {
  GltfBuffer b;
  const Triangle tri = add_triangle(b);
  const int d0 = b.add_floats({0, 1, 0, 0, 0, 0, 0, 0, 0}, "VEC3");
  const int d1 = b.add_floats({0, 0, 0, 0, 0, 2, 0, 0, 0}, "VEC3");
  const int times = b.add_floats({0, 1, 2}, "SCALAR");
  const int w = b.add_floats({0, 0, 1, 0.5f, 1, 0.5f}, "SCALAR");
  const std::string body = R"("meshes": [{"weights": [0.5, 0], "primitives": [{"attributes": {"POSITION": )" +
                           std::to_string(tri.position) + R"(, "NORMAL": )" + std::to_string(tri.normal) +
                           R"(}, "indices": )" + std::to_string(tri.indices) + R"(, "targets": [{"POSITION": )" +
                           std::to_string(d0) + R"(}, {"POSITION": )" + std::to_string(d1) + R"(}]}]}],
"nodes": [{"name": "animated", "mesh": 0, "translation": [0, 0, -1]},
          {"name": "node weights", "mesh": 0, "weights": [0, 1]},
          {"name": "mesh weights", "mesh": 0}],
"scenes": [{"nodes": [0, 1, 2]}],
"animations": [{"channels": [{"sampler": 0, "target": {"node": 0, "path": "weights"}}],
  "samplers": [{"input": )" + std::to_string(times) + R"(, "output": )" + std::to_string(w) + R"(}]}])";
  auto scene = Scene::load(write_gltf(test::scratch_dir("scene_morph"), "morph", b, body));
  ASSERT_TRUE(scene) << scene.error().message;
  ASSERT_EQ(scene->primitives().size(), 1u) << "one mesh, drawn by three nodes";
  EXPECT_TRUE(scene->primitives()[0].morphed);
  const FrameState f = scene->evaluate(0.5);
  ASSERT_EQ(f.instances.size(), 3u);
  for (const auto& inst : f.instances) ASSERT_TRUE(inst.deformed);
  // Animated weights at t = 0.5: (0.5, 0.25); then the node's translation (0,0,-1).
  expect_vec3(f.instances[0].world_positions[0], {0, 0.5f, -1}, kEps, "animated v0");
  expect_vec3(f.instances[0].world_positions[1], {1, 0, -0.5f}, kEps, "animated v1");
  // node.weights (0, 1) override mesh.weights.
  expect_vec3(f.instances[1].world_positions[0], {0, 0, 0}, kEps, "node weights v0");
  expect_vec3(f.instances[1].world_positions[1], {1, 0, 2}, kEps, "node weights v1");
  // mesh.weights (0.5, 0).
  expect_vec3(f.instances[2].world_positions[0], {0, 0.5f, 0}, kEps, "mesh weights v0");
  expect_vec3(f.instances[2].world_positions[1], {1, 0, 0}, kEps, "mesh weights v1");
}

TEST(SceneMeshes, StripsAndFansBecomeTrianglesWithFlatNormals) {
  GltfBuffer b;
  const int strip = b.add_floats({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0}, "VEC3");
  const int fan = b.add_floats({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, "VEC3");
  const std::string body = R"("meshes": [{"primitives": [
  {"attributes": {"POSITION": )" + std::to_string(strip) + R"(}, "mode": 5},
  {"attributes": {"POSITION": )" + std::to_string(fan) + R"(}, "mode": 6},
  {"attributes": {"POSITION": )" + std::to_string(fan) + R"(}, "mode": 1}]}],
"nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}])";
  auto scene = Scene::load(write_gltf(test::scratch_dir("scene_strips"), "strips", b, body));
  ASSERT_TRUE(scene) << scene.error().message;
  ASSERT_EQ(scene->primitives().size(), 2u) << "the LINES primitive is skipped";
  EXPECT_EQ(scene->warnings().size(), 1u);
  for (const auto& p : scene->primitives()) {
    EXPECT_EQ(p.indices.size(), 6u);  // 4 vertices -> 2 triangles
    ASSERT_EQ(p.normals.size(), p.positions.size());
    for (const auto& n : p.normals) expect_vec3(n, {0, 0, 1}, kEps, "flat normal (winding kept)");
    EXPECT_GE(p.material, 0) << "a default material is assigned";
  }
  ASSERT_EQ(scene->materials().size(), 1u);
  EXPECT_EQ(scene->materials()[0].name, "default");
  // Triangles of the strip: (v0, v1, v2) and (v1, v3, v2) of the original order (all corners distinct).
  const auto& p = scene->primitives()[0].positions;
  expect_vec3(p[3], {1, 0, 0}, kEps, "strip second triangle, first corner");
  expect_vec3(p[4], {1, 1, 0}, kEps, "strip second triangle, second corner");
}

TEST(SceneCamera, AutomaticCameraFramesTheSceneAndAddsAKeyLight) {
  GltfBuffer b;
  const Triangle tri = add_triangle(b);
  const std::string body = triangle_mesh(tri) + R"("nodes": [{"mesh": 0, "scale": [4, 4, 4]}], "scenes": [{"nodes": [0]}])";
  const auto path = write_gltf(test::scratch_dir("scene_autocam"), "autocam", b, body);
  for (auto mode : {CameraOptions::Path::Fixed, CameraOptions::Path::Orbit, CameraOptions::Path::Dolly}) {
    SceneLoadOptions opt;
    opt.camera.path = mode;
    opt.camera.path_period_s = 4.0;
    auto scene = Scene::load(path, opt);
    ASSERT_TRUE(scene) << scene.error().message;
    const glm::vec3 center = 0.5f * (scene->bounds_min() + scene->bounds_max());
    for (double t : {0.0, 1.0, 2.0, 3.0}) {
      const FrameState f = scene->evaluate(t);
      // The bounds' centre is on the view axis; every corner lies between near and far.
      const glm::vec3 c = glm::vec3(f.camera.view * glm::vec4(center, 1.0f));
      EXPECT_NEAR(c.x, 0.0f, 1e-4f);
      EXPECT_NEAR(c.y, 0.0f, 1e-4f);
      for (int k = 0; k < 8; ++k) {
        const glm::vec3 corner((k & 1) ? scene->bounds_max().x : scene->bounds_min().x,
                               (k & 2) ? scene->bounds_max().y : scene->bounds_min().y,
                               (k & 4) ? scene->bounds_max().z : scene->bounds_min().z);
        const float depth = -(f.camera.view * glm::vec4(corner, 1.0f)).z;
        EXPECT_GT(depth, f.camera.znear);
        EXPECT_LT(depth, f.camera.zfar);
      }
      ASSERT_EQ(f.lights.size(), 1u);
      EXPECT_EQ(f.lights[0].type, LightState::Type::Directional);
    }
    const glm::vec3 eye0 = glm::vec3(glm::inverse(scene->evaluate(0.0).camera.view)[3]);
    const glm::vec3 eye1 = glm::vec3(glm::inverse(scene->evaluate(1.0).camera.view)[3]);
    if (mode == CameraOptions::Path::Fixed) {
      expect_vec3(eye1, eye0, kEps, "fixed camera");
    } else if (mode == CameraOptions::Path::Orbit) {
      // A quarter turn about the vertical axis through the centre: same height, same distance, 90 degrees.
      EXPECT_NEAR(eye1.y, eye0.y, 1e-4f);
      const glm::vec2 a(eye0.x - center.x, eye0.z - center.z), c1(eye1.x - center.x, eye1.z - center.z);
      EXPECT_NEAR(glm::dot(a, c1), 0.0f, 1e-3f * glm::dot(a, a));
    } else {
      // Dolly: at a quarter period the distance is 1 - 0.35 * 0.5 = 82.5 % of the start.
      EXPECT_NEAR(glm::length(eye1 - center), 0.825f * glm::length(eye0 - center), 1e-4f * glm::length(eye0 - center));
    }
  }
}

TEST(SceneCamera, GltfCameraAndPunctualLightsFollowTheirNodes) {
  GltfBuffer b;
  const Triangle tri = add_triangle(b);
  const float s45 = std::sqrt(0.5f);
  const std::string body = triangle_mesh(tri) + R"(
"extensionsUsed": ["KHR_lights_punctual"], "extensionsRequired": ["KHR_lights_punctual"],
"extensions": {"KHR_lights_punctual": {"lights": [
  {"type": "spot", "color": [1, 0.5, 0.25], "intensity": 20, "spot": {"innerConeAngle": 0.1, "outerConeAngle": 0.5}},
  {"type": "point", "intensity": 3, "range": 7}]}},
"cameras": [{"type": "orthographic", "name": "ortho", "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 10}},
            {"type": "perspective", "name": "persp", "perspective": {"yfov": 0.5, "znear": 0.2, "zfar": 50, "aspectRatio": 1.5}}],
"nodes": [{"mesh": 0},
          {"camera": 0, "translation": [0, 0, 3]},
          {"camera": 1, "translation": [0, 0, 10]},
          {"translation": [1, 2, 3], "rotation": [)" + std::to_string(s45) + ", 0, 0, " + std::to_string(s45) + R"(],
           "extensions": {"KHR_lights_punctual": {"light": 0}}},
          {"translation": [-1, 0, 0], "extensions": {"KHR_lights_punctual": {"light": 1}}}],
"scenes": [{"nodes": [0, 1, 2, 3, 4]}])";
  const auto path = write_gltf(test::scratch_dir("scene_camera"), "camera", b, body);
  auto scene = Scene::load(path);
  ASSERT_TRUE(scene) << scene.error().message;
  const FrameState f = scene->evaluate(0.0);
  // The orthographic camera is skipped: the perspective one, 10 units up +Z, looking down -Z.
  EXPECT_EQ(f.camera.name, "persp");
  EXPECT_FLOAT_EQ(f.camera.yfov, 0.5f);
  EXPECT_FLOAT_EQ(f.camera.aspect, 1.5f);
  EXPECT_FLOAT_EQ(f.camera.znear, 0.2f);
  EXPECT_FLOAT_EQ(f.camera.zfar, 50.0f);
  expect_vec3(glm::vec3(f.camera.view * glm::vec4(0, 0, 0, 1)), {0, 0, -10}, kEps, "world origin in camera space");
  ASSERT_EQ(f.lights.size(), 2u);
  EXPECT_EQ(f.lights[0].type, LightState::Type::Spot);
  expect_vec3(f.lights[0].position, {1, 2, 3}, kEps, "spot position");
  // R_x(90) turns the light's -Z into +Y.
  expect_vec3(f.lights[0].direction, {0, 1, 0}, kEps, "spot direction");
  expect_vec3(f.lights[0].color, {1, 0.5f, 0.25f}, kEps, "spot colour");
  EXPECT_FLOAT_EQ(f.lights[0].intensity, 20.0f);
  EXPECT_FLOAT_EQ(f.lights[0].inner_cone, 0.1f);
  EXPECT_FLOAT_EQ(f.lights[0].outer_cone, 0.5f);
  EXPECT_EQ(f.lights[1].type, LightState::Type::Point);
  EXPECT_FLOAT_EQ(f.lights[1].range, 7.0f);
  expect_vec3(f.lights[1].position, {-1, 0, 0}, kEps, "point position");

  SceneLoadOptions opt;
  opt.camera.camera = "ortho";
  auto ortho = Scene::load(path, opt);
  ASSERT_FALSE(ortho);
  EXPECT_NE(ortho.error().message.find("orthographic"), std::string::npos) << ortho.error().message;
  opt.camera.camera = "1";
  auto by_index = Scene::load(path, opt);
  ASSERT_TRUE(by_index) << by_index.error().message;
  EXPECT_EQ(by_index->evaluate(0.0).camera.name, "persp");
  opt.camera.camera = "nope";
  auto missing = Scene::load(path, opt);
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().message.find("persp"), std::string::npos) << "lists the cameras: " << missing.error().message;
}

TEST(SceneEvaluate, ReusedFrameStateGivesTheSameResult) {
  auto scene = Scene::load(skin_scene(test::scratch_dir("scene_reuse")));
  ASSERT_TRUE(scene) << scene.error().message;
  FrameState reused;
  scene->evaluate(0.3, reused);
  scene->evaluate(0.7, reused);
  const FrameState fresh = scene->evaluate(0.7);
  ASSERT_EQ(reused.instances.size(), fresh.instances.size());
  for (std::size_t i = 0; i < fresh.instances.size(); ++i) {
    ASSERT_EQ(reused.instances[i].world_positions.size(), fresh.instances[i].world_positions.size());
    for (std::size_t v = 0; v < fresh.instances[i].world_positions.size(); ++v) {
      EXPECT_EQ(reused.instances[i].world_positions[v], fresh.instances[i].world_positions[v]);
    }
  }
}

// ---- bad input: every case gives an Input error with a useful message, never a crash ----

Error load_error(const std::string& path) {
  auto scene = Scene::load(path);
  EXPECT_FALSE(scene) << path << " loaded but should not";
  return scene ? Error{} : scene.error();
}

TEST(SceneBadInput, MalformedJsonMissingFilesAndBadReferences) {
  const auto dir = test::scratch_dir("scene_bad_input");
  {
    std::ofstream(dir / "malformed.gltf") << "{ \"asset\": {\"version\": \"2.0\"}, \"nodes\": [ {";
    const Error e = load_error((dir / "malformed.gltf").string());
    EXPECT_EQ(e.kind, ErrorKind::Input);
    EXPECT_NE(e.message.find("not a valid glTF"), std::string::npos) << e.message;
  }
  EXPECT_EQ(load_error((dir / "absent.gltf").string()).kind, ErrorKind::Input);

  GltfBuffer b;
  const Triangle tri = add_triangle(b);
  const std::string scene_nodes = R"("nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}])";
  {
    // Missing .bin: the buffer names a file that is not there.
    const auto path = write_gltf(dir, "nobin", b, triangle_mesh(tri) + scene_nodes);
    std::filesystem::remove(dir / "nobin.bin");
    const Error e = load_error(path);
    EXPECT_EQ(e.kind, ErrorKind::Input);
    EXPECT_FALSE(e.message.empty());
  }
  {
    // Accessor reading past its buffer view: count 30 on a 3-vertex view.
    GltfBuffer big;
    const Triangle t2 = add_triangle(big);
    auto path = write_gltf(dir, "range", big, triangle_mesh(t2) + scene_nodes);
    std::ifstream in(path);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string needle = "\"count\": 3, \"type\": \"VEC3\"";
    text.replace(text.find(needle), needle.size(), "\"count\": 30, \"type\": \"VEC3\"");
    std::ofstream(path) << text;
    const Error e = load_error(path);
    EXPECT_EQ(e.kind, ErrorKind::Input);
    EXPECT_NE(e.message.find("out of range"), std::string::npos) << e.message;
  }
  {
    // An index past the last vertex.
    GltfBuffer bad;
    const int pos = bad.add_floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3");
    const int idx = bad.add_ushorts({0, 1, 99}, "SCALAR");
    const auto path = write_gltf(dir, "index", bad,
                                 R"("meshes": [{"primitives": [{"attributes": {"POSITION": )" + std::to_string(pos) +
                                     R"(}, "indices": )" + std::to_string(idx) + "}]}],\n" + scene_nodes);
    const Error e = load_error(path);
    EXPECT_NE(e.message.find("index 99"), std::string::npos) << e.message;
  }
  {
    // A node naming a mesh that does not exist, and an accessor index that does not exist.
    const auto path = write_gltf(dir, "badmesh", b, triangle_mesh(tri) + R"("nodes": [{"mesh": 4}], "scenes": [{"nodes": [0]}])");
    EXPECT_NE(load_error(path).message.find("mesh 4"), std::string::npos);
    const auto path2 = write_gltf(dir, "badacc", b,
                                  R"("meshes": [{"primitives": [{"attributes": {"POSITION": 42}}]}],)" + scene_nodes);
    EXPECT_NE(load_error(path2).message.find("accessor 42"), std::string::npos);
  }
  {
    // Unsupported required extension: named in the message.
    const auto path = write_gltf(dir, "ext", b, triangle_mesh(tri) + scene_nodes +
                                                    R"(, "extensionsUsed": ["KHR_draco_mesh_compression"],
"extensionsRequired": ["KHR_draco_mesh_compression"])");
    const Error e = load_error(path);
    EXPECT_EQ(e.kind, ErrorKind::Input);
    EXPECT_NE(e.message.find("KHR_draco_mesh_compression"), std::string::npos) << e.message;
  }
  {
    // Missing texture image.
    GltfBuffer t;
    const Triangle t3 = add_triangle(t);
    const int uv = t.add_floats({0, 0, 1, 0, 0, 1}, "VEC2");
    const auto path = write_gltf(dir, "notex", t,
                                 R"("meshes": [{"primitives": [{"attributes": {"POSITION": )" +
                                     std::to_string(t3.position) + R"(, "TEXCOORD_0": )" + std::to_string(uv) +
                                     R"(}, "material": 0}]}],
"materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
"textures": [{"source": 0}], "images": [{"uri": "missing.png"}],)" +
                                     scene_nodes);
    const Error e = load_error(path);
    EXPECT_EQ(e.kind, ErrorKind::Input);
    EXPECT_NE(e.message.find("missing.png"), std::string::npos) << e.message;
  }
  {
    // A scene with nothing to draw.
    const auto path = write_gltf(dir, "empty", b, R"("nodes": [{"name": "empty"}], "scenes": [{"nodes": [0]}])");
    EXPECT_NE(load_error(path).message.find("no triangles"), std::string::npos);
  }
  {
    // A truncated .glb (the first half of a valid one).
    const auto glb = test::source_dir() / "assets" / "scenes" / "morph_test.glb";
    if (std::filesystem::exists(glb)) {
      std::ifstream in(glb, std::ios::binary);
      std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      std::ofstream(dir / "truncated.glb", std::ios::binary) << bytes.substr(0, bytes.size() / 2);
      EXPECT_EQ(load_error((dir / "truncated.glb").string()).kind, ErrorKind::Input);
    }
  }
  {
    // Unknown clip: a usage error listing the clips.
    SceneLoadOptions opt;
    opt.clip = "dance";
    auto scene = Scene::load(animation_scene(dir), opt);
    ASSERT_FALSE(scene);
    EXPECT_NE(scene.error().message.find("samplers"), std::string::npos) << scene.error().message;
  }
}

TEST(SceneBadInput, CyclesDecreasingKeysBadJointsAndNaN) {
  const auto dir = test::scratch_dir("scene_bad_input2");
  GltfBuffer b;
  const Triangle tri = add_triangle(b);
  const int times = b.add_floats({0, 2, 1}, "SCALAR");
  const int values = b.add_floats({0, 0, 0, 1, 0, 0, 2, 0, 0}, "VEC3");
  const int nan_values = b.add_floats({0, 0, 0, std::nanf(""), 0, 0, 2, 0, 0}, "VEC3");
  const int times_ok = b.add_floats({0, 1, 2}, "SCALAR");
  const std::string mesh = triangle_mesh(tri);
  {
    const auto path = write_gltf(dir, "cycle", b, mesh + R"("nodes": [{"mesh": 0, "children": [1]}, {"children": [0]}],
"scenes": [{"nodes": [0]}])");
    const Error e = load_error(path);
    EXPECT_EQ(e.kind, ErrorKind::Input);
    EXPECT_NE(e.message.find("cycle"), std::string::npos) << e.message;
  }
  {
    const auto path = write_gltf(dir, "keys", b, mesh + R"("nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}],
"animations": [{"channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}],
  "samplers": [{"input": )" + std::to_string(times) + R"(, "output": )" + std::to_string(values) + R"(}]}])");
    EXPECT_NE(load_error(path).message.find("increasing"), std::string::npos);
  }
  {
    const auto path = write_gltf(dir, "nan", b, mesh + R"("nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}],
"animations": [{"channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}],
  "samplers": [{"input": )" + std::to_string(times_ok) + R"(, "output": )" + std::to_string(nan_values) + R"(}]}])");
    EXPECT_NE(load_error(path).message.find("NaN"), std::string::npos);
  }
  {
    // A vertex bound to joint 3 of a two-joint skin.
    GltfBuffer s;
    const Triangle t = add_triangle(s);
    const int joints = s.add_ushorts({3, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}, "VEC4");
    const int weights = s.add_floats({1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0}, "VEC4");
    const auto path = write_gltf(dir, "joints", s,
                                 R"("meshes": [{"primitives": [{"attributes": {"POSITION": )" + std::to_string(t.position) +
                                     R"(, "JOINTS_0": )" + std::to_string(joints) + R"(, "WEIGHTS_0": )" +
                                     std::to_string(weights) + R"(}}]}],
"nodes": [{"mesh": 0, "skin": 0}, {"children": [2]}, {}], "skins": [{"joints": [1, 2]}], "scenes": [{"nodes": [0, 1]}])");
    const Error e = load_error(path);
    EXPECT_NE(e.message.find("joint 3"), std::string::npos) << e.message;
  }
}

}  // namespace
}  // namespace temporal
