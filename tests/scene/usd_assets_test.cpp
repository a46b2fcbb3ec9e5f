// The USD files of ../shared/assets/usd (skipped with a message when absent): OpenUSD's own linear blend
// skinning test (lbs.usda against the result OpenUSD baked into lbs.baked.usda, read independently with the
// layer parser), the Teapot through payload, sublayer, references and variants, the spinning pyramids through
// references, payloads, inherits and nested variants, and the crate file that must be refused.
#include "test_support.h"

#include "temporal/scene/scene.h"
#include "usd_layer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace temporal {
namespace {

std::optional<std::string> usd_asset(const std::string& relative) {
  auto root = test::shared_assets();
  if (!root) return std::nullopt;
  const auto path = *root / "usd" / relative;
  if (!std::filesystem::exists(path)) return std::nullopt;
  return path.string();
}

#define REQUIRE_USD(var, rel)                                     \
  const auto var = usd_asset(rel);                                \
  if (!var) GTEST_SKIP() << "../shared/assets/usd/" rel " is absent";

TEST(UsdAssets, LbsSkinningMatchesOpenUsdsBakedResult) {
  REQUIRE_USD(lbs, "OpenUSD/lbs.usda");
  REQUIRE_USD(baked, "OpenUSD/lbs.baked.usda");
  auto scene = Scene::load(*lbs);
  ASSERT_TRUE(scene) << scene.error().message;
  // The ground truth straight from the baked layer's text: points.timeSamples of every mesh, and normals.
  auto layer = usd::read_usda(*baked);
  ASSERT_TRUE(layer) << layer.error().message;
  const char* meshes[] = {"/Root/Mesh", "/Root/MeshWithFaceVaryingNormals", "/Root/MeshWithNormals"};
  ASSERT_EQ(scene->evaluate(0.0).instances.size(), 3u);
  double worst = 0.0, worst_normal = 0.0;
  int compared = 0;
  for (int m = 0; m < 3; ++m) {
    const usd::PrimSpec* spec = (*layer)->prim_at(meshes[m]);
    ASSERT_NE(spec, nullptr) << meshes[m];
    const auto& samples = spec->property("points")->time_samples;
    ASSERT_EQ(samples.size(), 30u) << meshes[m];
    const usd::PropertySpec* normals = spec->property("normals");
    const auto& indices = spec->property("faceVertexIndices")->default_value.numbers;
    for (std::size_t k = 0; k < samples.size(); ++k) {
      // Time code tc is (tc - startTimeCode 1) / 24 seconds.
      const FrameState f = scene->evaluate((samples[k].first - 1.0) / 24.0);
      const PrimitiveInstance& inst = f.instances[std::size_t(m)];
      ASSERT_TRUE(inst.deformed);
      const bool fv = normals && normals->metadata.size() && normals->metadata[0].second.text.at(0) == "faceVarying";
      // Vertices are points, or face-vertices in order when a primvar varies per face-vertex.
      for (std::size_t v = 0; v < inst.world_positions.size(); ++v) {
        const std::size_t p = fv ? std::size_t(indices[v]) : v;
        const double* expect = samples[k].second.numbers.data() + 3 * p;
        for (int c = 0; c < 3; ++c) worst = std::max(worst, std::fabs(double(inst.world_positions[v][c]) - expect[c]));
        ++compared;
        if (!normals) continue;
        const auto& nk = normals->time_samples.at(k).second.numbers;
        glm::vec3 n(float(nk[3 * v]), float(nk[3 * v + 1]), float(nk[3 * v + 2]));
        if (!fv) n = glm::vec3(float(nk[3 * p]), float(nk[3 * p + 1]), float(nk[3 * p + 2]));
        worst_normal = std::max(worst_normal, double(glm::length(glm::normalize(n) - inst.world_normals[v])));
      }
    }
  }
  std::printf("lbs.usda vs lbs.baked.usda: %d points at 30 time codes, max position error %.3g, max normal error %.3g\n",
              compared, worst, worst_normal);
  EXPECT_GT(compared, 1000);
  EXPECT_LT(worst, 1e-4);
  EXPECT_LT(worst_normal, 1e-4);
}

TEST(UsdAssets, BakedPointCachesReplayTheSameMotion) {
  REQUIRE_USD(lbs, "OpenUSD/lbs.usda");
  REQUIRE_USD(baked, "OpenUSD/lbs.baked.usda");
  auto a = Scene::load(*lbs), b = Scene::load(*baked);
  ASSERT_TRUE(a && b);
  EXPECT_DOUBLE_EQ(a->clip_duration(), 30.0 / 24.0);
  double worst = 0.0;
  for (double t : {0.0, 0.3 / 24.0, 7.5 / 24.0, 29.0 / 24.0}) {  // between samples too: both interpolate linearly
    const FrameState fa = a->evaluate(t), fb = b->evaluate(t);
    for (std::size_t i = 0; i < fa.instances.size(); ++i)
      for (std::size_t v = 0; v < fa.instances[i].world_positions.size(); ++v)
        worst = std::max(worst, double(glm::length(fa.instances[i].world_positions[v] - fb.instances[i].world_positions[v])));
  }
  // Skinning interpolates the joints' rotations, the cache the points: equal at the samples, close between.
  EXPECT_LT(worst, 0.05);
}

TEST(UsdAssets, TeapotThroughPayloadSubLayerReferencesAndVariants) {
  REQUIRE_USD(teapot, "Teapot/Teapot.usd");
  auto scene = Scene::load(*teapot);
  ASSERT_TRUE(scene) << scene.error().message;
  EXPECT_EQ(scene->format(), "USD");
  ASSERT_EQ(scene->primitives().size(), 1u) << "the Utah variant: one mesh";
  EXPECT_GT(scene->primitives()[0].indices.size(), 3000u);
  // Teapot.usd -> payload Teapot_Payload.usd -> subLayer Teapot_Materials.usd (shadingVariant
  // CeramicLimeGreen) -> reference Teapot_Geometry.usd -> variant Utah -> reference geo/UtahTeapot.usd.
  ASSERT_EQ(scene->materials().size(), 1u);
  EXPECT_EQ(scene->materials()[0].name, "Ceramic");
  EXPECT_EQ(scene->materials()[0].base_color_factor, glm::vec4(0.325f, 0.825f, 0.0f, 1.0f));
  EXPECT_NEAR(scene->bounds_max().y, 0.2295615f, 1e-5f);
  bool subdiv = false;
  for (const auto& w : scene->warnings()) subdiv = subdiv || w.find("control cage") != std::string::npos;
  EXPECT_TRUE(subdiv) << "catmullClark meshes are drawn as their cage, with a warning";
  EXPECT_EQ(scene->clip_duration(), 0.0);
}

TEST(UsdAssets, SpinningPyramidsAnimate) {
  REQUIRE_USD(path, "SubdivisionSurfaces/Creases_SpinningPyramids.usda");
  auto scene = Scene::load(*path);
  ASSERT_TRUE(scene) << scene.error().message;
  EXPECT_DOUBLE_EQ(scene->clip_duration(), 8.0) << "time codes 1..192 at 24 per second";
  const FrameState f0 = scene->evaluate(0.0), f1 = scene->evaluate(24.0 / 24.0);
  ASSERT_FALSE(f0.instances.empty());
  EXPECT_EQ(f0.camera.name, "Camera");
  EXPECT_NEAR(f0.camera.yfov, 2.0 * std::atan(0.5 * 0.089807145 / 1.8), 1e-6);
  // Time code 25 is 45 degrees of the spin (sample 25 of the file: (0.7071, 0, -0.7071) as its first row): the
  // change of the model matrix is a rotation of trace 1 + 2 cos 45 degrees.
  const glm::mat4 spin = glm::inverse(f0.instances[0].model) * f1.instances[0].model;
  EXPECT_NEAR(spin[0][0] + spin[1][1] + spin[2][2], 1.0 + std::sqrt(2.0), 1e-4) << "the pyramid turned 45 degrees";
  // Every pyramid is drawn in the colours of its faces (uniform displayColor, one material per colour).
  EXPECT_GT(scene->materials().size(), 3u);
}

TEST(UsdAssets, CrateFilesAreRefusedWithTheConversionCommand) {
  REQUIRE_USD(crate, "OpenUSD/top.geom.usd");
  auto scene = Scene::load(*crate);
  ASSERT_FALSE(scene);
  EXPECT_EQ(scene.error().kind, ErrorKind::Input);
  EXPECT_NE(scene.error().message.find("usdcat -o file.usda top.geom.usd"), std::string::npos) << scene.error().message;
}

TEST(UsdAssets, EveryTextLayerParses) {
  auto root = test::shared_assets();
  if (!root) GTEST_SKIP() << "../shared/assets is absent";
  int parsed = 0;
  for (const auto& e : std::filesystem::recursive_directory_iterator(*root / "usd")) {
    const auto ext = e.path().extension();
    if (ext != ".usd" && ext != ".usda") continue;
    auto layer = usd::read_usda(e.path().string());
    if (e.path().filename() == "top.geom.usd") {
      EXPECT_FALSE(layer);
      continue;
    }
    EXPECT_TRUE(layer) << e.path() << ": " << (layer ? "" : layer.error().file + ": " + layer.error().message);
    ++parsed;
  }
  EXPECT_GE(parsed, 17);
}

}  // namespace
}  // namespace temporal
