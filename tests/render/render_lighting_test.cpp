// The automatic lighting (issue 25 item 4, render.h LightingOptions): a scene without lights is lit by a key, a fill
// and an ambient term; the options scale each term by hand-checkable amounts; scenes with lights keep them; the
// dark-frame measure (RenderedFrame::dark_fraction) and its warning.
#include "test_support.h"

#include "../scene/gltf_writer.h"

#include "temporal/render/render.h"
#include "temporal/scene/scene.h"

#include <glm/geometric.hpp>
#include <glm/mat4x4.hpp>
#include <glm/gtc/matrix_inverse.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

namespace temporal {
namespace {

namespace fs = std::filesystem;

// One quad of half-size 1 through the origin with normal n (tangents t1 and n x t1), albedo (0.8, 0.6, 0.4),
// metallic 0, roughness 1, no camera; `light` adds a KHR_lights_punctual directional light of its own.
std::string write_quad(const fs::path& dir, const std::string& name, glm::vec3 n, glm::vec3 t1, bool light = false) {
  const glm::vec3 t2 = glm::cross(n, t1);
  const glm::vec3 v[4] = {-t1 - t2, t1 - t2, t1 + t2, -t1 + t2};
  std::vector<float> pos, nor;
  glm::vec3 lo(1e9f), hi(-1e9f);
  for (const glm::vec3& p : v) {
    pos.insert(pos.end(), {p.x, p.y, p.z});
    nor.insert(nor.end(), {n.x, n.y, n.z});
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  test::GltfBuffer b;
  const int ap = b.add_floats(pos, "VEC3"), an = b.add_floats(nor, "VEC3");
  const int ai = b.add_ushorts({0, 1, 2, 0, 2, 3}, "SCALAR");
  // Accessors need min/max on POSITION: the writer gives none, so the bounds are patched into the JSON below.
  std::string body = R"("scene": 0, "scenes": [{"nodes": [0)" + std::string(light ? ", 1" : "") + R"(]}],
"nodes": [{"mesh": 0})" + std::string(light ? R"(, {"rotation": [-0.5, 0, 0, 0.8660254], "extensions": {"KHR_lights_punctual": {"light": 0}}})" : "") + R"(],
"meshes": [{"primitives": [{"attributes": {"POSITION": )" + std::to_string(ap) + R"(, "NORMAL": )" + std::to_string(an) +
                     R"(}, "indices": )" + std::to_string(ai) + R"(, "material": 0}]}],
"materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.6, 0.4, 1], "metallicFactor": 0, "roughnessFactor": 1}}])";
  if (light)
    body += R"(,
"extensionsUsed": ["KHR_lights_punctual"],
"extensions": {"KHR_lights_punctual": {"lights": [{"type": "directional", "intensity": 2}]}})";
  const std::string path = test::write_gltf(dir, name, b, body);
  // Add the POSITION bounds glTF requires.
  std::ifstream in(path);
  std::string json((std::istreambuf_iterator<char>(in)), {});
  const std::string key = "\"count\": 4, \"type\": \"VEC3\"}";
  const auto at = json.find(key);
  char bounds[256];
  std::snprintf(bounds, sizeof bounds, "\"count\": 4, \"type\": \"VEC3\", \"min\": [%.9g, %.9g, %.9g], \"max\": [%.9g, %.9g, %.9g]}",
                lo.x, lo.y, lo.z, hi.x, hi.y, hi.z);
  json.replace(at, key.size(), bounds);
  std::ofstream(path) << json;
  return path;
}

struct Camera {
  glm::vec3 right, up, back;
};
// The automatic camera's axes: fixed by its direction (scene.h), whatever the geometry.
Camera camera_axes(const Scene& scene) {
  const glm::mat4 c = glm::inverse(scene.evaluate(0.0).camera.view);
  return {glm::vec3(c[0]), glm::vec3(c[1]), glm::vec3(c[2])};
}

struct Rendered {
  Image color;
  double dark = -1.0;
};
Rendered render(const Scene& scene, RenderOptions o) {
  o.width = 64;
  o.height = 48;
  o.color_jitter = JitterMode::None;
  o.outputs = RenderOutputs{false, false, false, true};
  auto r = Renderer::create(o, geometry_of(scene));
  EXPECT_TRUE(r) << r.error().message;
  if (!r) return {};
  const FrameState state = scene.evaluate(0.0);
  FrameInput in;
  in.current = &state;
  auto out = r->render(in);
  EXPECT_TRUE(out) << (out ? "" : out.error().message);
  if (!out) return {};
  return {*out->color, out->dark_fraction};
}

// A quad that faces the camera but turns its front away from the key light (normal = back - 1.5 up): the old
// lighting (the key alone) leaves every pixel black; the fill and the ambient light it.
class RenderLighting : public ::testing::Test {
 protected:
  void SetUp() override {
    // One folder per test: CTest runs this fixture's tests in parallel processes, and scratch_dir empties the folder
    // it returns (a shared one let a test read another's half-written quad).
    dir = test::scratch_dir(std::string("render_lighting-") +
                            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    auto probe = Scene::load(write_quad(dir, "probe", {0, 0, 1}, {1, 0, 0}));
    ASSERT_TRUE(probe) << probe.error().message;
    axes = camera_axes(*probe);
    n = glm::normalize(axes.back - 1.5f * axes.up);
    auto s = Scene::load(write_quad(dir, "unlit", n, glm::normalize(axes.right)));
    ASSERT_TRUE(s) << s.error().message;
    scene = std::make_unique<Scene>(std::move(*s));
  }
  fs::path dir;
  Camera axes;
  glm::vec3 n;
  std::unique_ptr<Scene> scene;
};

TEST_F(RenderLighting, TheRigLightsWhatTheKeyAloneLeavesBlack) {
  const SceneGeometry g = geometry_of(*scene);
  EXPECT_FALSE(g.own_lights);
  ASSERT_LT(glm::dot(n, -g.key_direction), 0.0f);  // the setup: the key cannot reach the quad's front
  ASSERT_GT(glm::dot(n, -g.fill_direction), 0.1f);  // ... and the fill reaches it (0.19)
  RenderOptions key_only;
  key_only.lighting.fill = key_only.lighting.ambient = 0.0f;
  const Rendered before = render(*scene, key_only), after = render(*scene, RenderOptions{});
  std::printf("dark fraction: key alone %.3f, key + fill + ambient %.3f\n", before.dark, after.dark);
  EXPECT_GT(before.dark, 0.5);
  EXPECT_GE(after.dark, 0.0);
  EXPECT_LT(after.dark, 0.5);
}

TEST_F(RenderLighting, FillAndAmbientGiveHandComputedRadiance) {
  const SceneGeometry g = geometry_of(*scene);
  const float c = std::max(glm::dot(n, -g.fill_direction), 0.0f);
  const float albedo[3] = {0.8f, 0.6f, 0.4f};
  // gi only (no ssao, no VPL flux with the key at 0): R,G,B = albedo (fill (n.l)+ + ambient).
  for (auto [fill, ambient] : {std::pair{0.4f, 0.15f}, {1.0f, 0.0f}, {0.0f, 0.5f}, {2.5f, 3.0f}}) {
    RenderOptions o;
    o.payload.direct = o.payload.shadow = o.payload.ssao = false;
    o.lighting.key = 0.0f;
    o.lighting.fill = fill;
    o.lighting.ambient = ambient;
    const Rendered r = render(*scene, o);
    int covered = 0;
    for (int ch = 0; ch < 3; ++ch) {
      const float* p = r.color.plane(std::string(1, "RGB"[ch]));
      const float expected = albedo[ch] * (fill * c + ambient);
      for (std::size_t i = 0; i < r.color.pixel_count(); ++i) {
        if (p[i] == 0.0f && expected != 0.0f) continue;  // background
        covered += ch == 0;
        ASSERT_NEAR(p[i], expected, 2e-5f * std::max(expected, 1.0f)) << "fill " << fill << " ambient " << ambient;
      }
    }
    EXPECT_GT(covered, 200) << "the quad covers too few pixels";
  }
}

// A USD DomeLight of radiance L (colour c) and nothing else: a Lambertian quad facing the camera reflects
// albedo x L x c (the hemisphere integral of albedo / pi x L (n.w)), as docs/usd.md says. Before this test the
// renderer gave albedo x L x c / pi.
TEST_F(RenderLighting, ADomeLightOfRadianceLMakesALambertianSurfaceReflectAlbedoTimesL) {
  const glm::vec3 r = glm::normalize(axes.right), u = glm::normalize(axes.up);
  char points[512];
  const glm::vec3 p[4] = {-r - u, r - u, r + u, -r + u};
  std::snprintf(points, sizeof points, "[(%.9g, %.9g, %.9g), (%.9g, %.9g, %.9g), (%.9g, %.9g, %.9g), (%.9g, %.9g, %.9g)]",
                p[0].x, p[0].y, p[0].z, p[1].x, p[1].y, p[1].z, p[2].x, p[2].y, p[2].z, p[3].x, p[3].y, p[3].z);
  const fs::path usda = dir / "dome.usda";
  std::ofstream(usda) << "#usda 1.0\ndef Mesh \"Quad\" {\n int[] faceVertexCounts = [4]\n int[] faceVertexIndices = [0, 1, 2, 3]\n"
                      << " point3f[] points = " << points << "\n"
                      << " color3f[] primvars:displayColor = [(0.8, 0.6, 0.4)]\n uniform token subdivisionScheme = \"none\"\n}\n"
                      << "def DomeLight \"Sky\" {\n float inputs:intensity = 0.5\n color3f inputs:color = (1, 0.5, 0.25)\n}\n";
  auto s = Scene::load(usda.string());
  ASSERT_TRUE(s) << s.error().message;
  RenderOptions o;
  o.payload.direct = o.payload.shadow = o.payload.ssao = false;
  o.lighting.key = o.lighting.fill = o.lighting.ambient = 0.0f;  // whatever the rig does, it adds nothing
  const Rendered out = render(*s, o);
  const float expected[3] = {0.8f * 0.5f, 0.6f * 0.25f, 0.4f * 0.125f};
  int covered = 0;
  for (int ch = 0; ch < 3; ++ch) {
    const float* px = out.color.plane(std::string(1, "RGB"[ch]));
    for (std::size_t i = 0; i < out.color.pixel_count(); ++i) {
      if (px[i] == 0.0f) continue;  // background
      covered += ch == 0;
      ASSERT_NEAR(px[i], expected[ch], 2e-5f) << "channel " << "RGB"[ch];
    }
  }
  EXPECT_GT(covered, 200) << "the quad covers too few pixels";
}

TEST_F(RenderLighting, TheKeyScalesDirectLightLinearly) {
  // A quad facing the camera is lit by the key: direct light is E (n.l) BRDF, so it doubles with --key-light.
  auto s = Scene::load(write_quad(dir, "lit", glm::normalize(axes.back), glm::normalize(axes.right)));
  ASSERT_TRUE(s) << s.error().message;
  RenderOptions o;
  o.payload.shadow = o.payload.ssao = o.payload.gi = false;
  const Rendered one = render(*s, o);
  o.lighting.key = 2.0f;
  const Rendered two = render(*s, o);
  o.lighting.key = 0.0f;
  const Rendered none = render(*s, o);
  int lit = 0;
  for (std::size_t i = 0; i < one.color.pixel_count(); ++i) {
    const float a = one.color.plane("R")[i];
    lit += a > 0.0f;
    EXPECT_NEAR(two.color.plane("R")[i], 2.0f * a, 1e-6f * std::max(a, 1.0f));
    EXPECT_EQ(none.color.plane("R")[i], 0.0f);
  }
  EXPECT_GT(lit, 200);
}

TEST_F(RenderLighting, ScenesWithLightsKeepThemUnlessAutoIsAsked) {
  auto s = Scene::load(write_quad(dir, "own_light", n, glm::normalize(axes.right), true));
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_TRUE(geometry_of(*s).own_lights);
  // The scene's own light: the rig's scales change nothing.
  RenderOptions a, b;
  b.lighting.key = 5.0f;
  b.lighting.fill = 0.0f;
  b.lighting.ambient = 7.0f;
  const Rendered ra = render(*s, a), rb = render(*s, b);
  for (std::size_t i = 0; i < ra.color.pixel_count(); ++i) ASSERT_EQ(ra.color.plane("G")[i], rb.color.plane("G")[i]);
  // --lights auto: the rig replaces the scene's light, so the scales apply.
  a.lighting.mode = b.lighting.mode = LightingOptions::Mode::Automatic;
  const Rendered auto_a = render(*s, a), auto_b = render(*s, b);
  double diff = 0.0;
  for (std::size_t i = 0; i < ra.color.pixel_count(); ++i) diff += std::fabs(auto_a.color.plane("G")[i] - auto_b.color.plane("G")[i]);
  EXPECT_GT(diff, 1.0);
}

TEST_F(RenderLighting, ABlackFrameIsMeasuredAsDarkAndWarnedAboutOnce) {
  RenderOptions o;
  o.lighting.key = o.lighting.fill = o.lighting.ambient = 0.0f;
  std::vector<std::string> warnings;
  o.warning = [&](const std::string& w) { warnings.push_back(w); };
  o.width = 64;
  o.height = 48;
  o.outputs = RenderOutputs{false, false, false, true};
  auto r = Renderer::create(o, geometry_of(*scene));
  ASSERT_TRUE(r) << r.error().message;
  const FrameState state = scene->evaluate(0.0);
  for (int f = 0; f < 3; ++f) {
    FrameInput in;
    in.frame = f;
    in.current = &state;
    auto out = r->render(in);
    ASSERT_TRUE(out);
    EXPECT_EQ(out->dark_fraction, 1.0);
  }
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("frame 0: 100 % of the covered pixels are below 1 % of the frame's maximum"), std::string::npos)
      << warnings[0];
}

}  // namespace
}  // namespace temporal
