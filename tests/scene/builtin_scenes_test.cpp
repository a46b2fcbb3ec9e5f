// The project's built-in scenes (assets/scenes): the generator reproduces the committed files byte for
// byte, and every scene loads, animates and has what its seed situation needs.
#include "test_support.h"

#include "temporal/scene/scene.h"

#include <glm/trigonometric.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>

namespace temporal {
namespace {

const std::vector<std::string> kScenes = {"walkers", "tower", "fan", "fence", "morph_test"};

std::filesystem::path scene_path(const std::string& name, const char* extension = ".glb") {
  return test::source_dir() / "assets" / "scenes" / (name + extension);
}

std::string read_bytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

int material_index(const Scene& s, const std::string& name) {
  for (std::size_t i = 0; i < s.materials().size(); ++i) {
    if (s.materials()[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

const PrimitiveInstance* instance_with_material(const Scene& s, const FrameState& f, const std::string& material) {
  const int m = material_index(s, material);
  for (const auto& inst : f.instances) {
    if (s.primitives()[static_cast<std::size_t>(inst.primitive)].material == m) return &inst;
  }
  return nullptr;
}

TEST(BuiltinScenes, GeneratorReproducesTheCommittedFiles) {
  const auto dir = test::scratch_dir("builtin_generator");
  std::string output;
  ASSERT_EQ(test::run_command(std::string("\"") + TEMPORAL_SCENE_GENERATOR + "\" \"" + dir.string() + "\"", &output), 0)
      << output;
  for (const auto& name : kScenes) {
    const std::string committed = read_bytes(scene_path(name));
    const std::string generated = read_bytes(dir / (name + ".glb"));
    ASSERT_FALSE(generated.empty()) << name;
    EXPECT_EQ(generated.size(), committed.size()) << name << ": regenerate assets/scenes (docs/scenes.md)";
    EXPECT_TRUE(generated == committed) << name << ".glb differs from the generator's output: regenerate it";
    EXPECT_LT(committed.size(), 1u << 20) << name << " is meant to stay under 1 MB";
    const std::string usda = read_bytes(dir / (name + ".usda"));
    EXPECT_FALSE(usda.empty()) << name;
    EXPECT_TRUE(usda == read_bytes(scene_path(name, ".usda"))) << name << ".usda differs from the generator's output: regenerate it";
  }
  int textures = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir / "textures")) {
    const auto committed = test::source_dir() / "assets" / "scenes" / "textures" / e.path().filename();
    EXPECT_TRUE(read_bytes(e.path()) == read_bytes(committed)) << committed << " differs from the generator's output";
    ++textures;
  }
  EXPECT_GE(textures, 5);
}

// The .usda copy of every built-in scene replays the .glb original: the same materials, draws, transforms,
// deformed vertices and camera at every frame of a 40 Hz sequence, bit for bit (the camera splines of tower and
// fence are baked to samples at 120 Hz that equal the glTF reader's spline values). Only skinned normals may
// differ in the last bits: UsdSkel blends the joints' normal matrices, glTF the joint matrices.
TEST(BuiltinScenes, UsdCopiesEvaluateLikeTheGltfOriginals) {
  for (const auto& name : kScenes) {
    SCOPED_TRACE(name);
    auto g = Scene::load(scene_path(name).string());
    auto u = Scene::load(scene_path(name, ".usda").string());
    ASSERT_TRUE(g && u) << (u ? "" : u.error().message);
    EXPECT_EQ(u->format(), "USD");
    EXPECT_TRUE(u->warnings().empty()) << u->warnings().front();
    EXPECT_DOUBLE_EQ(u->clip_duration(), g->clip_duration());
    ASSERT_EQ(u->materials().size(), g->materials().size());
    for (std::size_t i = 0; i < g->materials().size(); ++i) {
      const SceneMaterial &a = g->materials()[i], &b = u->materials()[i];
      EXPECT_EQ(a.base_color_factor, b.base_color_factor) << a.name;
      EXPECT_EQ(a.roughness, b.roughness) << a.name;
      EXPECT_EQ(a.metallic, b.metallic) << a.name;
      EXPECT_EQ(a.alpha_mode, b.alpha_mode) << a.name;
      EXPECT_EQ(a.double_sided, b.double_sided) << a.name;
      EXPECT_EQ(a.base_color_texture < 0, b.base_color_texture < 0) << a.name;
      if (a.base_color_texture >= 0 && b.base_color_texture >= 0) {
        EXPECT_TRUE(g->textures()[std::size_t(a.base_color_texture)].rgba8 == u->textures()[std::size_t(b.base_color_texture)].rgba8)
            << a.name << ": the PNG beside the .usda decodes to the .glb's pixels";
      }
    }
    float model = 0.0f, vertex = 0.0f, normal = 0.0f, view = 0.0f, fov = 0.0f;
    for (int frame = 0; frame < 480; frame += 7) {
      const FrameState a = g->evaluate(frame / 40.0), b = u->evaluate(frame / 40.0);
      ASSERT_EQ(a.instances.size(), b.instances.size());
      for (std::size_t i = 0; i < a.instances.size(); ++i) {
        const PrimitiveInstance &x = a.instances[i], &y = b.instances[i];
        EXPECT_EQ(x.id, y.id);
        ASSERT_EQ(x.deformed, y.deformed);
        for (int c = 0; c < 4; ++c) model = std::max(model, glm::length(x.model[c] - y.model[c]));
        for (std::size_t v = 0; v < x.world_positions.size(); ++v) {
          vertex = std::max(vertex, glm::length(x.world_positions[v] - y.world_positions[v]));
          normal = std::max(normal, glm::length(x.world_normals[v] - y.world_normals[v]));
        }
      }
      for (int c = 0; c < 4; ++c) view = std::max(view, glm::length(a.camera.view[c] - b.camera.view[c]));
      fov = std::max(fov, std::fabs(a.camera.yfov - b.camera.yfov));
      ASSERT_EQ(a.lights.size(), b.lights.size());
    }
    EXPECT_EQ(model, 0.0f);
    EXPECT_EQ(vertex, 0.0f);
    EXPECT_LT(normal, 1e-6f);
    EXPECT_EQ(view, 0.0f);
    EXPECT_EQ(fov, 0.0f);
  }
}

TEST(BuiltinScenes, EverySceneLoadsWithItsCameraLightsAndMotion) {
  for (const auto& file : kScenes) {
    for (const char* extension : {".glb", ".usda"}) {
    const std::string name = file + extension;
    SCOPED_TRACE(name);
    auto scene = Scene::load(scene_path(file, extension).string());
    ASSERT_TRUE(scene) << scene.error().message;
    EXPECT_TRUE(scene->warnings().empty());
    EXPECT_GT(scene->clip_duration(), 0.0);
    ASSERT_EQ(scene->camera_names().size(), 1u);
    const FrameState f0 = scene->evaluate(0.0), f1 = scene->evaluate(0.1);
    EXPECT_EQ(f0.camera.name, scene->camera_names()[0]) << "the scene's own camera, not the automatic one";
    EXPECT_GE(f0.lights.size(), 1u);
    EXPECT_FALSE(scene->textures().empty()) << "at least the ground's procedural texture";
    // Something moves between t = 0 and t = 0.1: the camera, a node or a deformed vertex.
    float moved = glm::length(glm::vec3(f1.camera.view[3] - f0.camera.view[3]));
    for (std::size_t i = 0; i < f0.instances.size(); ++i) {
      const auto& a = f0.instances[i];
      const auto& b = f1.instances[i];
      for (int c = 0; c < 4; ++c) moved = std::max(moved, glm::length(a.model[c] - b.model[c]));
      for (std::size_t v = 0; v < a.world_positions.size(); ++v) {
        moved = std::max(moved, glm::length(a.world_positions[v] - b.world_positions[v]));
      }
    }
    EXPECT_GT(moved, 1e-3f);
    }
  }
}

TEST(BuiltinScenes, WalkersAreSkinnedUnderAStaticCameraAndCheap) {
  auto scene = Scene::load(scene_path("walkers").string());
  ASSERT_TRUE(scene) << scene.error().message;
  std::size_t triangles = 0, skinned = 0;
  for (const auto& p : scene->primitives()) {
    triangles += p.indices.size() / 3;
    skinned += p.skinned;
  }
  EXPECT_EQ(skinned, 2u) << "two skinned quadrupeds";
  EXPECT_LT(triangles, 5000u) << "the demo default stays cheap";
  const FrameState a = scene->evaluate(0.0), b = scene->evaluate(1.3);
  EXPECT_EQ(a.camera.view, b.camera.view) << "static camera, as in the horses scene";
  // Legs move relative to the body: the hoof-to-hoof distances change between two instants.
  const PrimitiveInstance* bay = instance_with_material(*scene, a, "coat_bay");
  ASSERT_NE(bay, nullptr);
  ASSERT_TRUE(bay->deformed);
  // Each animal trots round its circle once per clip: after a quarter clip it has turned 90 degrees.
  glm::vec3 c0(0.0f), c1(0.0f);
  for (const auto& p : bay->world_positions) c0 += p;
  const FrameState later = scene->evaluate(1.0);
  for (const auto& p : instance_with_material(*scene, later, "coat_bay")->world_positions) c1 += p;
  c0 /= static_cast<float>(bay->world_positions.size());
  c1 /= static_cast<float>(bay->world_positions.size());
  EXPECT_NEAR(std::atan2(c0.z, c0.x) - std::atan2(c1.z, c1.x), glm::radians(90.0f), glm::radians(8.0f))
      << "centroid angle at t = 0 and t = 1 (counter-clockwise seen from above)";
}

TEST(BuiltinScenes, FanBladesTurnAtOneAndAHalfRevolutionsPerSecond) {
  auto scene = Scene::load(scene_path("fan").string());
  ASSERT_TRUE(scene) << scene.error().message;
  const FrameState a = scene->evaluate(0.0), b = scene->evaluate(0.1);
  const PrimitiveInstance* ba = instance_with_material(*scene, a, "blades_white");
  const PrimitiveInstance* bb = instance_with_material(*scene, b, "blades_white");
  ASSERT_TRUE(ba && bb);
  EXPECT_FALSE(ba->deformed) << "rigid: a model matrix only";
  // 1.5 rev/s clockwise about the viewing axis (+Z): 0.1 s -> -54 degrees.
  const glm::mat4 rel = bb->model * glm::inverse(ba->model);
  EXPECT_NEAR(std::atan2(rel[0][1], rel[0][0]), glm::radians(-54.0f), 1e-3f);
  EXPECT_NEAR(rel[2][2], 1.0f, 1e-4f) << "the rotation axis is Z";
}

TEST(BuiltinScenes, TowerCameraFollowsItsCircle) {
  auto scene = Scene::load(scene_path("tower").string());
  ASSERT_TRUE(scene) << scene.error().message;
  // Keys every second on a circle of radius 11.5, height 2.2 + 0.8 sin(2 theta), theta = 2 pi t / 12.
  const glm::vec3 eye3 = glm::vec3(glm::inverse(scene->evaluate(3.0).camera.view)[3]);
  EXPECT_NEAR(eye3.x, 11.5f, 1e-3f);
  EXPECT_NEAR(eye3.y, 2.2f, 1e-3f);
  EXPECT_NEAR(eye3.z, 0.0f, 1e-3f);
  // Between keys the CUBICSPLINE with the circle's velocity as tangents stays on the circle (within 1 cm).
  for (double t : {0.5, 1.25, 7.7}) {
    const glm::vec3 e = glm::vec3(glm::inverse(scene->evaluate(t).camera.view)[3]);
    EXPECT_NEAR(std::hypot(e.x, e.z), 11.5f, 0.01f) << t;
  }
}

TEST(BuiltinScenes, FenceHasCutOutFoliageAndThinGeometry) {
  auto scene = Scene::load(scene_path("fence").string());
  ASSERT_TRUE(scene) << scene.error().message;
  const int leaves = material_index(*scene, "leaves");
  ASSERT_GE(leaves, 0);
  const SceneMaterial& m = scene->materials()[static_cast<std::size_t>(leaves)];
  EXPECT_EQ(m.alpha_mode, SceneMaterial::AlphaMode::Mask);
  EXPECT_TRUE(m.double_sided);
  ASSERT_GE(m.base_color_texture, 0);
  // The leaf atlas is a real cut-out: both transparent and opaque texels.
  const auto& tex = scene->textures()[static_cast<std::size_t>(m.base_color_texture)];
  std::size_t opaque = 0;
  for (std::size_t i = 3; i < tex.rgba8.size(); i += 4) opaque += tex.rgba8[i] == 255;
  const std::size_t texels = tex.rgba8.size() / 4;
  EXPECT_GT(opaque, texels / 10);
  EXPECT_LT(opaque, texels * 9 / 10);
}

TEST(BuiltinScenes, MorphTestFlagIsMorphed) {
  auto scene = Scene::load(scene_path("morph_test").string());
  ASSERT_TRUE(scene) << scene.error().message;
  const FrameState f = scene->evaluate(0.5);
  const PrimitiveInstance* flag = instance_with_material(*scene, f, "flag");
  ASSERT_NE(flag, nullptr);
  EXPECT_TRUE(scene->primitives()[static_cast<std::size_t>(flag->primitive)].morphed);
  EXPECT_TRUE(flag->deformed);
  // At t = 0.5 the weights are (1, 0.5): z = 0.18 u sin(2 pi u) + 0.5 * 0.12 u cos(pi v), 0.06 m at u = 1, v = 0.
  float max_z = 0.0f;
  for (const auto& p : flag->world_positions) max_z = std::max(max_z, p.z);
  EXPECT_GT(max_z, 0.04f);
}

}  // namespace
}  // namespace temporal
