// Scene replay against the Khronos glTF sample assets in ../shared/assets/gltf (skipped when absent).
// Expected values are either read off the files' keyframes by hand (InterpolationTest) or computed here,
// independently of the library, straight from the file's data with tinygltf (skinning, morphing).
#include "test_support.h"

#include "temporal/scene/scene.h"

#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <tiny_gltf.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>

namespace temporal {
namespace {

std::optional<std::string> asset(const std::string& relative) {
  auto root = test::shared_assets();
  if (!root) return std::nullopt;
  const auto path = *root / "gltf" / relative;
  if (!std::filesystem::exists(path)) return std::nullopt;
  return path.string();
}

#define REQUIRE_ASSET(var, rel)                                                  \
  const auto var = asset(rel);                                                   \
  if (!var) GTEST_SKIP() << "../shared/assets/gltf/" rel " is absent";

glm::mat4 model_of(const FrameState& f, const Scene& s, int node) {
  for (const auto& inst : f.instances) {
    if (inst.node == node) return inst.model;
  }
  ADD_FAILURE() << "no instance for node " << node;
  return glm::mat4(1.0f);
}

// ---- an independent reference: raw accessor reads and node transforms straight from tinygltf ----

tinygltf::Model load_raw(const std::string& path) {
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string err, warn;
  const bool ok = path.size() > 4 && path.substr(path.size() - 4) == ".glb"
                      ? loader.LoadBinaryFromFile(&model, &err, &warn, path)
                      : loader.LoadASCIIFromFile(&model, &err, &warn, path);
  EXPECT_TRUE(ok) << err;
  return model;
}

// Element i, component c of a float / unsigned accessor (no sparse, as in these assets).
double raw(const tinygltf::Model& m, int accessor, std::size_t i, int c) {
  const auto& a = m.accessors[static_cast<std::size_t>(accessor)];
  const auto& bv = m.bufferViews[static_cast<std::size_t>(a.bufferView)];
  const int stride = a.ByteStride(bv);
  const unsigned char* p = m.buffers[static_cast<std::size_t>(bv.buffer)].data.data() + bv.byteOffset + a.byteOffset +
                           i * static_cast<std::size_t>(stride);
  switch (a.componentType) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: { float v; std::memcpy(&v, p + 4 * c, 4); return v; }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return p[c];
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { std::uint16_t v; std::memcpy(&v, p + 2 * c, 2); return v; }
    default: ADD_FAILURE() << "component type " << a.componentType; return 0.0;
  }
}

// World matrices of every node at key `key` of animation `anim` (all its samplers share one input).
std::vector<glm::mat4> reference_world(const tinygltf::Model& m, int anim, std::size_t key) {
  const std::size_t n = m.nodes.size();
  std::vector<glm::vec3> t(n, glm::vec3(0.0f)), s(n, glm::vec3(1.0f));
  std::vector<glm::quat> r(n, glm::quat(1, 0, 0, 0));
  std::vector<glm::mat4> local(n, glm::mat4(1.0f));
  std::vector<char> animated(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const auto& node = m.nodes[i];
    if (node.translation.size() == 3) t[i] = glm::vec3(node.translation[0], node.translation[1], node.translation[2]);
    if (node.rotation.size() == 4) r[i] = glm::quat(float(node.rotation[3]), float(node.rotation[0]), float(node.rotation[1]), float(node.rotation[2]));
    if (node.scale.size() == 3) s[i] = glm::vec3(node.scale[0], node.scale[1], node.scale[2]);
    if (node.matrix.size() == 16) local[i] = glm::make_mat4(node.matrix.data());
  }
  for (const auto& ch : m.animations[static_cast<std::size_t>(anim)].channels) {
    const auto& smp = m.animations[static_cast<std::size_t>(anim)].samplers[static_cast<std::size_t>(ch.sampler)];
    const auto i = static_cast<std::size_t>(ch.target_node);
    animated[i] = 1;
    if (ch.target_path == "translation") t[i] = glm::vec3(raw(m, smp.output, key, 0), raw(m, smp.output, key, 1), raw(m, smp.output, key, 2));
    if (ch.target_path == "scale") s[i] = glm::vec3(raw(m, smp.output, key, 0), raw(m, smp.output, key, 1), raw(m, smp.output, key, 2));
    if (ch.target_path == "rotation") {
      r[i] = glm::normalize(glm::quat(float(raw(m, smp.output, key, 3)), float(raw(m, smp.output, key, 0)),
                                      float(raw(m, smp.output, key, 1)), float(raw(m, smp.output, key, 2))));
    }
  }
  std::vector<int> parent(n, -1);
  for (std::size_t i = 0; i < n; ++i) {
    for (int c : m.nodes[i].children) parent[static_cast<std::size_t>(c)] = static_cast<int>(i);
  }
  std::vector<glm::mat4> world(n);
  std::function<glm::mat4(std::size_t)> w = [&](std::size_t i) -> glm::mat4 {
    glm::mat4 l = local[i];
    if (m.nodes[i].matrix.size() != 16 || animated[i]) {
      l = glm::translate(glm::mat4(1.0f), t[i]) * glm::mat4_cast(r[i]) * glm::scale(glm::mat4(1.0f), s[i]);
    }
    return parent[i] >= 0 ? w(static_cast<std::size_t>(parent[i])) * l : l;
  };
  for (std::size_t i = 0; i < n; ++i) world[i] = w(i);
  return world;
}

// Checks the skinned vertices of `path` at key `key` of the first animation against
// sum_i w_i * world(joint_i) * inverseBind_i * v computed from the raw file.
void check_skinning(const std::string& path, std::size_t key, float tolerance) {
  auto scene = Scene::load(path);
  ASSERT_TRUE(scene) << scene.error().message;
  const tinygltf::Model m = load_raw(path);
  const auto& smp0 = m.animations[0].samplers[0];
  for (const auto& smp : m.animations[0].samplers) ASSERT_EQ(smp.input, smp0.input) << "one shared key time line";
  const double t = raw(m, smp0.input, key, 0);
  const std::vector<glm::mat4> world = reference_world(m, 0, key);

  int skinned_node = -1;
  for (std::size_t i = 0; i < m.nodes.size(); ++i) {
    if (m.nodes[i].skin >= 0) skinned_node = static_cast<int>(i);
  }
  ASSERT_GE(skinned_node, 0);
  const auto& node = m.nodes[static_cast<std::size_t>(skinned_node)];
  const auto& skin = m.skins[static_cast<std::size_t>(node.skin)];
  const auto& prim = m.meshes[static_cast<std::size_t>(node.mesh)].primitives[0];
  ASSERT_EQ(prim.indices < 0 || prim.attributes.count("NORMAL"), true)
      << "vertex order must be kept by the loader (it is, unless flat normals de-index an indexed mesh)";
  const int pos = prim.attributes.at("POSITION"), jnt = prim.attributes.at("JOINTS_0"), wgt = prim.attributes.at("WEIGHTS_0");

  const FrameState f = scene->evaluate(t);
  const PrimitiveInstance* inst = nullptr;
  for (const auto& i : f.instances) {
    if (i.node == skinned_node) inst = &i;
  }
  ASSERT_NE(inst, nullptr);
  ASSERT_TRUE(inst->deformed);
  const std::size_t count = m.accessors[static_cast<std::size_t>(pos)].count;
  ASSERT_EQ(inst->world_positions.size(), count);
  float worst = 0.0f;
  for (std::size_t v = 0; v < count; ++v) {
    glm::mat4 xf(0.0f);
    double wsum = 0.0;
    for (int c = 0; c < 4; ++c) wsum += raw(m, wgt, v, c);
    for (int c = 0; c < 4; ++c) {
      const double w = raw(m, wgt, v, c) / wsum;
      if (w == 0.0) continue;
      const auto j = static_cast<std::size_t>(raw(m, jnt, v, c));
      glm::mat4 ibm(1.0f);
      if (skin.inverseBindMatrices >= 0) {
        for (int e = 0; e < 16; ++e) glm::value_ptr(ibm)[e] = static_cast<float>(raw(m, skin.inverseBindMatrices, j, e));
      }
      xf += static_cast<float>(w) * (world[static_cast<std::size_t>(skin.joints[j])] * ibm);
    }
    const glm::vec3 p(raw(m, pos, v, 0), raw(m, pos, v, 1), raw(m, pos, v, 2));
    const glm::vec3 expected = glm::vec3(xf * glm::vec4(p, 1.0f));
    const glm::vec3& actual = inst->world_positions[v];
    ASSERT_TRUE(std::isfinite(actual.x) && std::isfinite(actual.y) && std::isfinite(actual.z));
    worst = std::max(worst, glm::length(actual - expected));
  }
  EXPECT_LE(worst, tolerance) << path << " at t = " << t << " s: largest vertex difference";
  for (const auto& n : inst->world_normals) EXPECT_NEAR(glm::length(n), 1.0f, 1e-4f);
}

TEST(SampleAssets, SimpleSkinHandComputedVertices) {
  REQUIRE_ASSET(path, "SimpleSkin/SimpleSkin.gltf");
  auto scene = Scene::load(*path);
  ASSERT_TRUE(scene) << scene.error().message;
  // Both inverse bind matrices are T(-0.5, -1, 0); joint 0 (node 1) sits at (0,1,0), joint 1 (node 2) is its
  // child at its origin, turned about Z by the animation. t = 0: no rotation -> every vertex moves by (-0.5,0,0).
  FrameState f = scene->evaluate(0.0);
  const auto& rest = scene->primitives()[0].positions;
  for (std::size_t v = 0; v < rest.size(); ++v) {
    const glm::vec3 d = f.instances[0].world_positions[v] - (rest[v] - glm::vec3(0.5f, 0, 0));
    EXPECT_LT(glm::length(d), 1e-5f) << "vertex " << v;
  }
  // t = 1: key 2, rotation (0,0,0.707,0.707) = 90 degrees about Z.
  // Rest vertex (0,2,0), weight 1 on joint 1: T(0,1,0) R90 (-0.5,1,0) = (0,1,0) + (-1,-0.5,0) = (-1,0.5,0).
  // Rest vertex (0,1,0), 0.5 / 0.5: joint 0 gives (-0.5,1,0), joint 1 (0,1,0) + R90(-0.5,0,0) = (0,0.5,0).
  // (The file has no normals: flat normals give one vertex per triangle corner, so look them up by rest position.)
  f = scene->evaluate(1.0);
  const auto& p = f.instances[0].world_positions;
  int found_top = 0, found_mid = 0;
  for (std::size_t v = 0; v < rest.size(); ++v) {
    if (rest[v] == glm::vec3(0, 2, 0)) {
      ++found_top;
      EXPECT_NEAR(p[v].x, -1.0f, 1e-4f);
      EXPECT_NEAR(p[v].y, 0.5f, 1e-4f);
    }
    if (rest[v] == glm::vec3(0, 1, 0)) {
      ++found_mid;
      EXPECT_NEAR(p[v].x, -0.25f, 1e-4f);
      EXPECT_NEAR(p[v].y, 0.75f, 1e-4f);
    }
  }
  EXPECT_GT(found_top, 0);
  EXPECT_GT(found_mid, 0);
}

TEST(SampleAssets, RiggedSimpleMatchesIndependentSkinning) {
  REQUIRE_ASSET(path, "RiggedSimple/RiggedSimple.glb");
  check_skinning(*path, 10, 1e-4f);
  check_skinning(*path, 30, 1e-4f);
}

TEST(SampleAssets, FoxMatchesIndependentSkinningAndStaysBounded) {
  REQUIRE_ASSET(path, "Fox/Fox.glb");
  check_skinning(*path, 7, 2e-3f);  // fox units are centimetres: 2e-3 is 20 micrometres
  auto scene = Scene::load(*path);
  ASSERT_TRUE(scene);
  EXPECT_EQ(scene->clip_names(), (std::vector<std::string>{"Survey", "Walk", "Run"}));
  const glm::vec3 size = scene->bounds_max() - scene->bounds_min();
  // Every vertex of every frame of the clip stays finite and near the rest bounds.
  for (int k = 0; k < 40; ++k) {
    const FrameState f = scene->evaluate(k * scene->clip_duration() / 40.0);
    for (const auto& p : f.instances[0].world_positions) {
      ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
      EXPECT_TRUE(glm::all(glm::greaterThan(p, scene->bounds_min() - size))) << k;
      EXPECT_TRUE(glm::all(glm::lessThan(p, scene->bounds_max() + size))) << k;
    }
  }
  SceneLoadOptions run;
  run.clip = "Run";
  auto running = Scene::load(*path, run);
  ASSERT_TRUE(running);
  EXPECT_LT(running->clip_duration(), scene->clip_duration());
}

TEST(SampleAssets, AnimatedMorphCubeMatchesIndependentMorphing) {
  REQUIRE_ASSET(path, "AnimatedMorphCube/AnimatedMorphCube.glb");
  auto scene = Scene::load(*path);
  ASSERT_TRUE(scene) << scene.error().message;
  const tinygltf::Model m = load_raw(*path);
  const auto& smp = m.animations[0].samplers[0];
  const auto& prim = m.meshes[0].primitives[0];
  const int pos = prim.attributes.at("POSITION");
  const std::vector<glm::mat4> world = reference_world(m, 0, 0);
  for (std::size_t key : {20u, 45u}) {
    const double t = raw(m, smp.input, key, 0);
    const double w0 = raw(m, smp.output, 2 * key, 0), w1 = raw(m, smp.output, 2 * key + 1, 0);
    const FrameState f = scene->evaluate(t);
    ASSERT_TRUE(f.instances[0].deformed);
    float worst = 0.0f;
    for (std::size_t v = 0; v < m.accessors[static_cast<std::size_t>(pos)].count; ++v) {
      glm::vec3 p(raw(m, pos, v, 0), raw(m, pos, v, 1), raw(m, pos, v, 2));
      const int d0 = prim.targets[0].at("POSITION"), d1 = prim.targets[1].at("POSITION");
      p += static_cast<float>(w0) * glm::vec3(raw(m, d0, v, 0), raw(m, d0, v, 1), raw(m, d0, v, 2));
      p += static_cast<float>(w1) * glm::vec3(raw(m, d1, v, 0), raw(m, d1, v, 1), raw(m, d1, v, 2));
      const glm::vec3 expected = glm::vec3(world[0] * glm::vec4(p, 1.0f));
      worst = std::max(worst, glm::length(f.instances[0].world_positions[v] - expected));
    }
    EXPECT_LT(worst, 1e-3f) << "key " << key << " (weights " << w0 << ", " << w1 << "); the cube is 200 units wide";
    EXPECT_GT(w0 + w1, 0.0) << "a key where the cube is morphed";
  }
}

TEST(SampleAssets, InterpolationTestHandValues) {
  REQUIRE_ASSET(path, "InterpolationTest/InterpolationTest.glb");
  SceneLoadOptions all;
  all.clip = "all";
  auto scene = Scene::load(*path, all);
  ASSERT_TRUE(scene) << scene.error().message;
  ASSERT_EQ(scene->clip_names().size(), 9u);
  const double k1 = 10.0 / 24.0, k2 = 20.0 / 24.0;  // key times of the translation clips (frames 10, 20 at 24 fps)
  // Step Translation (node 8): keys y = 6.665 @0, 10 @0.4583, 6 @0.8333.
  EXPECT_NEAR(model_of(scene->evaluate(0.3), *scene, 8)[3].y, 6.6652f, 1e-3f);
  EXPECT_NEAR(model_of(scene->evaluate(0.6), *scene, 8)[3].y, 10.0f, 1e-4f);
  // Linear Translation (node 10): y from 10 @k1 to 6 @k2 -> 8 halfway.
  EXPECT_NEAR(model_of(scene->evaluate(0.5 * (k1 + k2)), *scene, 10)[3].y, 8.0f, 1e-3f);
  // CubicSpline Translation (node 9), all tangents 0: halfway h00 = h01 = 0.5 -> 8; at a quarter
  // h00 = 0.84375, h01 = 0.15625 -> 0.84375 * 10 + 0.15625 * 6 = 9.375.
  EXPECT_NEAR(model_of(scene->evaluate(0.5 * (k1 + k2)), *scene, 9)[3].y, 8.0f, 1e-3f);
  EXPECT_NEAR(model_of(scene->evaluate(k1 + 0.25 * (k2 - k1)), *scene, 9)[3].y, 9.375f, 1e-3f);
  // Scale clips: keys 1 @0.0417, 0.5 @0.4167, 1 @0.875.
  const double s1 = 0.4167, s2 = 0.875;
  EXPECT_NEAR(model_of(scene->evaluate(0.3), *scene, 0)[0].x, 1.0f, 1e-4f);           // STEP: still 1
  EXPECT_NEAR(model_of(scene->evaluate(0.6), *scene, 0)[0].x, 0.5f, 1e-4f);           // STEP: 0.5
  EXPECT_NEAR(model_of(scene->evaluate(0.5 * (s1 + s2)), *scene, 3)[0].x, 0.75f, 1e-3f);  // LINEAR
  EXPECT_NEAR(model_of(scene->evaluate(0.5 * (s1 + s2)), *scene, 4)[0].x, 0.75f, 1e-3f);  // CUBIC, zero tangents
  // Linear Rotation (node 7): keys (0,0,-0.3827,0.9239) = -45 degrees about Z @0.4167 and
  // (0,0,-0.7071,0.7071) = -90 degrees @0.875: halfway -67.5 degrees.
  const glm::mat4 r = model_of(scene->evaluate(0.5 * (0.4167 + 0.875)), *scene, 7);
  EXPECT_NEAR(std::atan2(r[0].y, r[0].x), glm::radians(-67.5f), 2e-3f);
  // Step Rotation (node 5): -45 degrees from 0.4167 to 0.875.
  const glm::mat4 rs = model_of(scene->evaluate(0.6), *scene, 5);
  EXPECT_NEAR(std::atan2(rs[0].y, rs[0].x), glm::radians(-45.0f), 1e-3f);
}

TEST(SampleAssets, EveryModelLoadsAndEvaluatesFinite) {
  auto root = test::shared_assets();
  if (!root) GTEST_SKIP() << "../shared/assets is absent";
  int loaded = 0;
  for (const char* rel : {"AnimatedCube/AnimatedCube.gltf", "BoxAnimated/BoxAnimated.gltf", "CesiumMan/CesiumMan.glb",
                          "CesiumMilkTruck/CesiumMilkTruck.glb", "RiggedFigure/RiggedFigure.glb", "Cameras/Cameras.gltf",
                          "AlphaBlendModeTest/AlphaBlendModeTest.glb", "TextureCoordinateTest/TextureCoordinateTest.glb",
                          "SheenChair/SheenChair.gltf"}) {
    const auto path = asset(rel);
    if (!path) continue;
    auto scene = Scene::load(*path);
    ASSERT_TRUE(scene) << rel << ": " << scene.error().message;
    ++loaded;
    const FrameState f = scene->evaluate(0.37);
    EXPECT_FALSE(f.instances.empty()) << rel;
    EXPECT_FALSE(f.lights.empty()) << rel;
    for (const auto& inst : f.instances) {
      for (const auto& p : inst.world_positions) ASSERT_TRUE(std::isfinite(p.x + p.y + p.z)) << rel;
    }
    for (const auto& t : scene->textures()) {
      EXPECT_EQ(t.rgba8.size(), static_cast<std::size_t>(t.width) * static_cast<std::size_t>(t.height) * 4u) << rel;
    }
  }
  EXPECT_GT(loaded, 0);
  // AlphaBlendModeTest has MASK and BLEND materials.
  if (const auto path = asset("AlphaBlendModeTest/AlphaBlendModeTest.glb")) {
    auto scene = Scene::load(*path);
    ASSERT_TRUE(scene);
    int mask = 0, blend = 0;
    for (const auto& mtl : scene->materials()) {
      mask += mtl.alpha_mode == SceneMaterial::AlphaMode::Mask;
      blend += mtl.alpha_mode == SceneMaterial::AlphaMode::Blend;
    }
    EXPECT_GT(mask, 0);
    EXPECT_GT(blend, 0);
  }
}

}  // namespace
}  // namespace temporal
