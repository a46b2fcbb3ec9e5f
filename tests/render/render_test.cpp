// Renderer tests on scenes built in code (synthetic_scene.h): motion vectors checked by warping, the
// regular jitter pattern's coverage, determinism, and hand-computed payload values.
#include "synthetic_scene.h"
#include "test_support.h"

#include "temporal/render/render.h"
#include "temporal/core/jitter.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <vector>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace temporal {
namespace {

using test::SyntheticScene;

RenderOptions small_options(int w = 96, int h = 72) {
  RenderOptions o;
  o.width = w;
  o.height = h;
  o.factor = 4;
  o.reference_spp = 2;
  o.payload.shadow_map_size = 256;
  o.payload.vpl_count = 64;
  o.payload.rsm_size = 32;
  o.payload.ssao_directions = 4;
  o.payload.ssao_steps = 4;
  return o;
}

// Frame 0 of `state` (no previous frame) from a new renderer for `geometry`: the set-up of the one-frame payload
// tests. The renderer's error or the frame's.
Expected<RenderedFrame> render_still(const RenderOptions& o, const SceneGeometry& geometry, const FrameState& state) {
  auto r = Renderer::create(o, geometry);
  if (!r) return r.error();
  FrameInput in;
  in.current = &state;
  return r->render(in);
}

Image render_gbuffer(Renderer& r, const SyntheticScene& scene, int frame, double fps) {
  const FrameState cur = scene.evaluate(frame / fps);
  const FrameState prev = scene.evaluate((frame - 1) / fps);
  FrameInput in;
  in.frame = frame;
  in.fps = fps;
  in.current = &cur;
  in.previous = frame > 0 ? &prev : nullptr;
  auto out = r.render(in);
  EXPECT_TRUE(out) << (out ? "" : out.error().message);
  return out ? *out->gbuffer : Image();
}

struct WarpResult {
  int considered = 0;
  int matched = 0;
  double fraction() const { return considered ? double(matched) / considered : 0.0; }
};

// Follows each pixel of frame N with id `only_id` (0: every surface) to frame N-1 at p + motion (nearest
// pixel) and counts where frame N-1 shows the same id, the same albedo (a checker texture: position along
// the surface) and a depth within 5%. motion_scale 1 is the test; -1 (a sign error) is the control.
WarpResult warp_match(const Image& cur, const Image& prev, std::uint32_t only_id, float motion_scale) {
  WarpResult r;
  const int w = cur.width(), h = cur.height();
  const auto* id = cur.uint_plane("id");
  const auto* id_p = prev.uint_plane("id");
  const float *mx = cur.plane("motion.X"), *my = cur.plane("motion.Y");
  const float *a = cur.plane("albedo.R"), *a_p = prev.plane("albedo.R");
  const float *d = cur.plane("depth.Z"), *d_p = prev.plane("depth.Z");
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = std::size_t(y) * w + x;
      if (id[i] == 0 || (only_id && id[i] != only_id)) continue;
      const float qx = x + 0.5f + motion_scale * mx[i];
      const float qy = y + 0.5f + motion_scale * my[i];
      // The 2 x 2 pixels around q (the bilinear footprint of a history fetch): one must show the surface.
      const int xi = int(std::floor(qx - 0.5f)), yi = int(std::floor(qy - 0.5f));
      if (xi < 0 || yi < 0 || xi + 1 >= w || yi + 1 >= h) continue;  // left the image
      ++r.considered;
      bool found = false;
      for (int dy = 0; dy < 2 && !found; ++dy)
        for (int dx = 0; dx < 2 && !found; ++dx) {
          const std::size_t j = std::size_t(yi + dy) * w + (xi + dx);
          found = id_p[j] == id[i] && std::fabs(a_p[j] - a[i]) < 0.05f && std::fabs(d_p[j] - d[i]) < 0.05f * d[i];
        }
      r.matched += found;
      if (!found && std::getenv("RENDER_TEST_DEBUG")) {
        const std::size_t j = std::size_t(yi) * w + xi;
        std::printf("p(%d,%d) id %u->%u a %.3f->%.3f d %.3f->%.3f m(%.2f,%.2f)\n", x, y, id[i], id_p[j], a[i], a_p[j], d[i], d_p[j], mx[i], my[i]);
      }
    }
  return r;
}

void check_motion(unsigned motion, std::uint32_t moving_id) {
  SyntheticScene scene;
  scene.motion = motion;
  RenderOptions o = small_options(128, 96);
  o.outputs = RenderOutputs{true, false, false, false};
  auto r = Renderer::create(o, scene.geometry());
  ASSERT_TRUE(r) << r.error().message;
  const double fps = 8.0;  // large steps: several pixels per frame, so zero motion must fail
  const Image prev = render_gbuffer(*r, scene, 9, fps);
  const Image cur = render_gbuffer(*r, scene, 10, fps);
  const WarpResult with = warp_match(cur, prev, moving_id, 1.0f);
  const WarpResult without = warp_match(cur, prev, moving_id, -1.0f);
  ASSERT_GT(with.considered, 200) << "too few pixels of the moving surface are visible";
  std::printf("motion %u: %d pixels, %.4f match with motion, %.4f negated\n", motion, with.considered, with.fraction(),
              without.fraction());
  EXPECT_GT(with.fraction(), 0.95) << with.matched << " of " << with.considered;
  // Control: negated vectors (a sign error) must match clearly worse, or the test proves nothing.
  EXPECT_LT(without.fraction(), with.fraction() - 0.1) << "negated motion matched " << without.fraction();
}

TEST(RenderMotion, CameraMotionWarpsDepthIdAndAlbedo) { check_motion(SyntheticScene::kCamera, 0); }
TEST(RenderMotion, NodeAnimationWarpsTheMovingBox) { check_motion(SyntheticScene::kNode, 2); }
TEST(RenderMotion, DeformedVerticesWarp) { check_motion(SyntheticScene::kDeform, 3); }
TEST(RenderMotion, AllMotionsTogether) { check_motion(SyntheticScene::kCamera | SyntheticScene::kNode | SyntheticScene::kDeform, 0); }

TEST(RenderMotion, StaticSceneHasZeroMotionAndFrameZeroToo) {
  SyntheticScene scene;
  RenderOptions o = small_options(64, 48);
  o.outputs = RenderOutputs{true, false, false, false};
  auto r = Renderer::create(o, scene.geometry());
  ASSERT_TRUE(r) << r.error().message;
  for (int frame : {0, 5}) {
    const Image g = render_gbuffer(*r, scene, frame, 40.0);
    for (const char* c : {"motion.X", "motion.Y"})
      for (std::size_t i = 0; i < g.pixel_count(); ++i) ASSERT_EQ(g.plane(c)[i], 0.0f) << c << " frame " << frame;
  }
}

TEST(RenderMotion, BackgroundCarriesCameraMotionAndFarDepth) {
  SyntheticScene scene;
  scene.motion = SyntheticScene::kCamera;
  RenderOptions o = small_options(64, 48);
  o.outputs = RenderOutputs{true, false, false, false};
  auto r = Renderer::create(o, scene.geometry());
  ASSERT_TRUE(r) << r.error().message;
  const Image g = render_gbuffer(*r, scene, 10, 10.0);
  // Top-left pixel sees the sky (the camera looks down at the ground from 3.5 units up).
  ASSERT_EQ(g.uint_plane("id")[0], 0u);
  EXPECT_EQ(g.plane("depth.Z")[0], 50.0f);
  EXPECT_EQ(g.plane("N.X")[0], 0.0f);
  // The camera orbits to +angle (its right): distant points shift... only the sign is robust: non-zero.
  EXPECT_GT(std::fabs(g.plane("motion.X")[0]), 0.1f);
}

// prevDepth.Z (the depth the surface point under the pixel had in the previous frame, seed 000 section 3.2's
// warped depth): equal to depth.Z bit for bit where nothing moved and on frame 0.
TEST(RenderPrevDepth, StaticSceneAndFrameZeroEqualDepthBitForBit) {
  for (unsigned motion : {unsigned(SyntheticScene::kStatic),
                          unsigned(SyntheticScene::kCamera | SyntheticScene::kNode | SyntheticScene::kDeform)}) {
    SyntheticScene scene;
    scene.motion = motion;
    RenderOptions o = small_options(64, 48);
    o.outputs = RenderOutputs{true, false, false, false};
    auto r = Renderer::create(o, scene.geometry());
    ASSERT_TRUE(r) << r.error().message;
    for (int frame : {0, 5}) {
      if (motion != SyntheticScene::kStatic && frame != 0) continue;  // a moving scene: frame 0 only
      const Image g = render_gbuffer(*r, scene, frame, 40.0);
      const float *z = g.plane("depth.Z"), *zp = g.plane("prevDepth.Z");
      ASSERT_NE(zp, nullptr);
      ASSERT_EQ(std::memcmp(z, zp, g.pixel_count() * sizeof(float)), 0) << "motion " << motion << " frame " << frame;
    }
  }
}

// A camera dolly along its view axis: the camera of frame N is d nearer (along its forward axis) than that of
// frame N-1, nothing else moves, so every surface point was d further away: prevDepth = depth + d. Float
// rounding of the two view transforms (depths ~5-10, coordinates ~7): within 1e-5 relative (about 10 ulps).
// Background: clipFar, like depth.
TEST(RenderPrevDepth, CameraDollyAddsTheDollyDistance) {
  SyntheticScene scene;
  RenderOptions o = small_options(64, 48);
  o.outputs = RenderOutputs{true, false, false, false};
  auto r = Renderer::create(o, scene.geometry());
  ASSERT_TRUE(r) << r.error().message;
  const float d = 0.75f;
  FrameState cur = scene.evaluate(0.0), prev = scene.evaluate(0.0);
  const glm::vec3 eye(0.0f, 3.5f, 7.0f), target(0.0f, 0.5f, 0.0f);
  const glm::vec3 forward = glm::normalize(target - eye);
  cur.camera.view = glm::lookAt(eye, target, glm::vec3(0, 1, 0));
  prev.camera.view = glm::lookAt(eye - d * forward, target, glm::vec3(0, 1, 0));
  FrameInput in;
  in.frame = 1;
  in.fps = 40.0;
  in.current = &cur;
  in.previous = &prev;
  auto out = r->render(in);
  ASSERT_TRUE(out) << out.error().message;
  const Image& g = *out->gbuffer;
  const float *z = g.plane("depth.Z"), *zp = g.plane("prevDepth.Z");
  const std::uint32_t* id = g.uint_plane("id");
  ASSERT_NE(zp, nullptr);
  std::size_t surface = 0;
  for (std::size_t i = 0; i < g.pixel_count(); ++i) {
    if (id[i] == 0) {
      EXPECT_EQ(zp[i], 50.0f) << i;  // clipFar
      continue;
    }
    ++surface;
    ASSERT_NEAR(zp[i], z[i] + d, 1e-5f * (z[i] + d)) << "pixel " << i << " depth " << z[i];
  }
  EXPECT_GT(surface, g.pixel_count() / 2);
}

// The jitter tests' set-up: 64x48, direct light only (no random terms), the low-resolution payload and the
// unjittered full-resolution colour.
static RenderOptions jitter_test_options() {
  RenderOptions o = small_options(64, 48);
  o.payload = *parse_payload_terms("direct", o.payload);
  o.outputs = RenderOutputs{false, true, false, true};
  o.color_jitter = JitterMode::None;
  return o;
}

// Renders the k*k frames of the regular pattern of the static synthetic scene and hands each frame's
// low-resolution payload and full-resolution colour to visit(frame, low, full). False when rendering fails.
static bool render_pattern(const SyntheticScene& scene, const RenderOptions& o,
                           const std::function<void(int, const Image&, const Image&)>& visit) {
  auto r = Renderer::create(o, scene.geometry());
  EXPECT_TRUE(r) << r.error().message;
  if (!r) return false;
  const FrameState state = scene.evaluate(0.0);
  for (int frame = 0; frame < o.factor * o.factor; ++frame) {
    FrameInput in;
    in.frame = frame;
    in.current = &state;
    auto out = r->render(in);
    EXPECT_TRUE(out) << out.error().message;
    if (!out) return false;
    visit(frame, *out->shade, *out->color);
  }
  return true;
}

TEST(RenderJitter, RegularPatternCoversEveryFullResPixelOnce) {
  // Static scene: the low-res sample of frame i at (x, y) must be full-res pixel (k x + sx, k y + sy), i.e.
  // equal the unjittered full-res payload there.
  SyntheticScene scene;
  RenderOptions o = jitter_test_options();
  // Texture filtering must depend on the sample point only: no mip levels, and bilinear for both
  // magnification (full res) and minification (low res).
  o.mipmaps = false;
  scene.textures[0].nearest = false;
  const int k = o.factor;
  std::vector<int> hits(std::size_t(o.width) * o.height, 0);
  int compared = 0, equal = 0;
  ASSERT_TRUE(render_pattern(scene, o, [&](int frame, const Image& low, const Image& full) {
    ASSERT_EQ(low.width(), o.width / k);
    ASSERT_EQ(low.metadata().jitter_index.value_or(-1), frame);
    const glm::vec2 j = *low.metadata().jitter;
    const glm::ivec2 sub = regular_subpixel(k, frame);  // the pattern's dispersed order (conventions "Jitter")
    const int sx = sub.x, sy = sub.y;
    EXPECT_FLOAT_EQ(j.x, (sx + 0.5f) / k - 0.5f);
    EXPECT_FLOAT_EQ(j.y, (sy + 0.5f) / k - 0.5f);
    for (int y = 0; y < low.height(); ++y)
      for (int x = 0; x < low.width(); ++x) {
        const int fx = k * x + sx, fy = k * y + sy;
        ++hits[std::size_t(fy) * o.width + fx];
        for (const char* c : {"R", "G", "B"}) {
          const float a = low.plane(c)[std::size_t(y) * low.width() + x];
          const float b = full.plane(c)[std::size_t(fy) * o.width + fx];
          ++compared;
          if (std::fabs(a - b) <= 1e-3f * std::max(1.0f, std::fabs(b))) ++equal;
          else if (std::getenv("RENDER_TEST_DEBUG")) std::printf("f%d low(%d,%d) full(%d,%d) %s %.5f vs %.5f\n", frame, x, y, fx, fy, c, a, b);
        }
      }
  }));
  for (std::size_t i = 0; i < hits.size(); ++i) ASSERT_EQ(hits[i], 1) << "pixel " << i;
  // Triangle edges may rasterise differently by a rounding; everything else is the same sample.
  EXPECT_GT(double(equal) / compared, 0.99) << equal << " of " << compared;
}

// Mean |low - full| over the low-res samples of k*k frames of the static synthetic scene (direct light only),
// textures mipmapped: the low-res sample (x, y) against full-res pixel (k x + sx, k y + sy).
static double mean_sample_difference(std::optional<float> shade_mip_bias) {
  SyntheticScene scene;
  RenderOptions o = jitter_test_options();
  o.shade_mip_bias = shade_mip_bias;
  scene.textures[0].nearest = false;
  const int k = o.factor;
  double sum = 0;
  std::size_t n = 0;
  const bool ok = render_pattern(scene, o, [&](int frame, const Image& low, const Image& full) {
    const glm::ivec2 sub = regular_subpixel(k, frame);  // the pattern's dispersed order (conventions "Jitter")
    const int sx = sub.x, sy = sub.y;
    for (int y = 0; y < low.height(); ++y)
      for (int x = 0; x < low.width(); ++x)
        for (const char* c : {"R", "G", "B"}) {
          sum += std::fabs(low.plane(c)[std::size_t(y) * low.width() + x] -
                           full.plane(c)[std::size_t(k * y + sy) * o.width + k * x + sx]);
          ++n;
        }
  });
  if (!ok) return 1e9;
  return sum / double(n);
}

TEST(RenderJitter, LowResolutionPayloadReadsTexturesAtTheFullResolutionMipLevel) {
  // With mipmaps, the low-res pass's screen derivatives are k times the full-res ones; the default LOD bias
  // -log2(k) makes it read the same mip level, so its samples match the full-res pixels (up to llvmpipe's
  // per-quad LOD); without the bias they are the textures prefiltered for the low resolution (the 8x8 checker
  // of the synthetic ground blurs towards its mean).
  const double biased = mean_sample_difference(std::nullopt);
  const double unbiased = mean_sample_difference(0.0f);
  EXPECT_LT(biased, 0.004) << "unbiased " << unbiased;
  EXPECT_GT(unbiased, 5.0 * biased) << "biased " << biased;
}

TEST(RenderJitter, DispersedOrderIsBayer) {
  // The 4x4 Bayer matrix [[0 8 2 10] [12 4 14 6] [3 11 1 9] [15 7 13 5]] (rows y): index i is the cell holding i.
  const int bayer4[4][4] = {{0, 8, 2, 10}, {12, 4, 14, 6}, {3, 11, 1, 9}, {15, 7, 13, 5}};
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) EXPECT_EQ(regular_subpixel(4, bayer4[y][x]), glm::ivec2(x, y)) << x << "," << y;
  // 2x2: (0,0) (1,1) (1,0) (0,1). k = 3, ranked on the top-left 3x3 of the 4x4 matrix (0 8 2 / 12 4 14 / 3 11 1):
  EXPECT_EQ(regular_subpixel(2, 1), glm::ivec2(1, 1));
  EXPECT_EQ(regular_subpixel(2, 3), glm::ivec2(0, 1));
  const glm::ivec2 k3[9] = {{0, 0}, {2, 2}, {2, 0}, {0, 2}, {1, 1}, {1, 0}, {1, 2}, {0, 1}, {2, 1}};
  for (int i = 0; i < 9; ++i) EXPECT_EQ(regular_subpixel(3, i), k3[i]) << i;
  // Every k is a permutation of the k x k cells; each run of 4 frames of k = 4 has one sample per 2x2 quadrant.
  for (int k = 1; k <= 8; ++k) {
    std::vector<int> seen(std::size_t(k * k), 0);
    for (int i = 0; i < k * k; ++i) {
      const glm::ivec2 s = regular_subpixel(k, i);
      ASSERT_TRUE(s.x >= 0 && s.x < k && s.y >= 0 && s.y < k) << k << " " << i;
      ++seen[std::size_t(s.y * k + s.x)];
      EXPECT_EQ(regular_subpixel(k, i, true), glm::ivec2(i % k, i / k));
    }
    for (int c : seen) EXPECT_EQ(c, 1) << "k = " << k;
  }
  for (int run = 0; run < 4; ++run) {
    int quadrants = 0;
    for (int i = 4 * run; i < 4 * run + 4; ++i) {
      const glm::ivec2 s = regular_subpixel(4, i);
      quadrants |= 1 << ((s.y / 2) * 2 + s.x / 2);
    }
    EXPECT_EQ(quadrants, 0xf) << "frames " << 4 * run << "-" << 4 * run + 3;
  }
  EXPECT_EQ(frame_jitter(JitterMode::RegularRaster, 7, 4, 0), glm::vec2(0.375f, -0.125f));
  EXPECT_EQ(frame_jitter(JitterMode::Regular, 7, 4, 0), glm::vec2(-0.125f, 0.375f));
}

TEST(RenderJitter, PatternsAndProjection) {
  EXPECT_EQ(regular_jitter(4, 0), glm::vec2(-0.375f, -0.375f));
  EXPECT_EQ(regular_jitter(4, 7), glm::vec2(-0.125f, 0.375f));       // dispersed order: index 7 is (1, 3)
  EXPECT_EQ(regular_jitter(4, 7, true), glm::vec2(0.375f, -0.125f));  // raster order: (3, 1)
  EXPECT_EQ(regular_jitter_index(17, 4), 1);
  EXPECT_EQ(regular_jitter_index(-1, 4), 15);
  EXPECT_FLOAT_EQ(radical_inverse(1, 2), 0.5f);
  EXPECT_FLOAT_EQ(radical_inverse(5, 3), 7.0f / 9.0f);  // 5 = 12 in base 3 -> 0.21 = 2/3 + 1/9
  EXPECT_EQ(frame_jitter(JitterMode::Random, 3, 4, 7), frame_jitter(JitterMode::Random, 3, 4, 7));
  EXPECT_NE(frame_jitter(JitterMode::Random, 3, 4, 7), frame_jitter(JitterMode::Random, 4, 4, 7));
  for (int f = 0; f < 50; ++f)
    for (JitterMode m : {JitterMode::Halton, JitterMode::Random}) {
      const glm::vec2 j = frame_jitter(m, f, 4, 1);
      EXPECT_GE(j.x, -0.5f);
      EXPECT_LT(j.x, 0.5f);
      EXPECT_GE(j.y, -0.5f);
      EXPECT_LT(j.y, 0.5f);
    }
  // A point projecting to pixel centre (10.5, 20.5) of a 100 x 50 image moves to (10.5 - jx, 20.5 - jy):
  // the pixel (10, 20) then samples image position (10.5 + jx, 20.5 + jy).
  const glm::mat4 p(1.0f);
  const glm::vec2 jit(0.25f, -0.125f);
  const glm::mat4 pj = jitter_projection(p, jit, 100, 50);
  const glm::vec4 ndc(2.0f * 10.5f / 100 - 1, 1 - 2.0f * 20.5f / 50, 0, 1);
  const glm::vec4 q = pj * ndc;
  EXPECT_NEAR((q.x * 0.5f + 0.5f) * 100, 10.5f - jit.x, 1e-4);
  EXPECT_NEAR((0.5f - q.y * 0.5f) * 50, 20.5f - jit.y, 1e-4);
}

TEST(RenderDeterminism, TwoRenderersGiveBitIdenticalImages) {
  SyntheticScene scene;
  scene.motion = SyntheticScene::kCamera | SyntheticScene::kNode | SyntheticScene::kDeform;
  RenderOptions o = small_options(64, 48);
  const FrameState cur = scene.evaluate(0.3), prev = scene.evaluate(0.2);
  FrameInput in;
  in.frame = 3;
  in.fps = 10.0;
  in.current = &cur;
  in.previous = &prev;
  std::vector<RenderedFrame> runs;
  for (int run = 0; run < 2; ++run) {
    auto r = Renderer::create(o, scene.geometry());
    ASSERT_TRUE(r) << r.error().message;
    auto out = r->render(in);
    ASSERT_TRUE(out) << out.error().message;
    runs.push_back(std::move(*out));
  }
  for (auto member : {&RenderedFrame::gbuffer, &RenderedFrame::shade, &RenderedFrame::reference, &RenderedFrame::color}) {
    const Image& a = *(runs[0].*member);
    const Image& b = *(runs[1].*member);
    ASSERT_EQ(a.channel_names(), b.channel_names());
    for (const auto& c : a.channel_names()) {
      const void* pa = a.channel_type(c) == ChannelType::UInt ? static_cast<const void*>(a.uint_plane(c)) : a.plane(c);
      const void* pb = b.channel_type(c) == ChannelType::UInt ? static_cast<const void*>(b.uint_plane(c)) : b.plane(c);
      EXPECT_EQ(std::memcmp(pa, pb, a.pixel_count() * 4), 0) << "channel " << c << " differs";
    }
  }
  // A different frame changes the random terms (SSAO pattern, VPL set, colour jitter).
  auto r = Renderer::create(o, scene.geometry());
  in.frame = 4;
  auto other = r->render(in);
  ASSERT_TRUE(other);
  EXPECT_NE(std::memcmp(other->color->plane("R"), runs[0].color->plane("R"), other->color->pixel_count() * 4), 0);
}

// A camera straight above a lit plane: hand-computed payload values.
struct PlaneScene {
  std::vector<ScenePrimitive> prims;
  std::vector<SceneMaterial> mats;
  std::vector<SceneTexture> texs;
  PlaneScene(bool wall) {
    ScenePrimitive g;
    SyntheticScene::add_quad(g, {-5, 0, 5}, {10, 0, 0}, {0, 0, -10}, {1, 1});
    g.material = 0;
    prims.push_back(g);
    if (wall) {  // a wall at x = 1 facing -x, bouncing light onto the floor
      ScenePrimitive w;
      SyntheticScene::add_quad(w, {1, 0, 5}, {0, 4, 0}, {0, 0, -10}, {1, 1});
      w.material = 0;
      prims.push_back(w);
    }
    SceneMaterial m;
    m.base_color_factor = glm::vec4(0.5f, 0.5f, 0.5f, 1.0f);
    m.roughness = 1.0f;
    mats.push_back(m);
  }
  SceneGeometry geometry() const {
    SceneGeometry g;
    g.primitives = &prims;
    g.materials = &mats;
    g.textures = &texs;
    g.bounds_min = {-5, 0, -5};
    g.bounds_max = {5, 4, 5};
    return g;
  }
  FrameState state() const {
    FrameState f;
    f.camera.view = glm::lookAt(glm::vec3(0, 5, 0), glm::vec3(0, 0, 0), glm::vec3(0, 0, -1));
    f.camera.yfov = 0.5f;
    f.camera.znear = 0.1f;
    f.camera.zfar = 20.0f;
    LightState l;
    // Straight down for the plane; slanted towards +x when the wall must catch light to bounce.
    l.direction = prims.size() > 1 ? glm::normalize(glm::vec3(0.7f, -1.0f, 0.0f)) : glm::vec3(0, -1, 0);
    l.intensity = 2.0f;
    l.color = {1.0f, 1.0f, 1.0f};
    f.lights.push_back(l);
    for (std::size_t i = 0; i < prims.size(); ++i) {
      PrimitiveInstance inst;
      inst.primitive = int(i);
      inst.id = 1;
      f.instances.push_back(inst);
    }
    return f;
  }
};

TEST(RenderPayload, DirectLightOnAPlaneMatchesTheFormula) {
  PlaneScene scene(false);
  RenderOptions o = small_options(64, 64);
  o.outputs = RenderOutputs{true, false, true, false};
  o.reference_spp = 1;
  auto out = render_still(o, scene.geometry(), scene.state());
  ASSERT_TRUE(out) << out.error().message;
  const Image& ref = *out->reference;
  const Image& gb = *out->gbuffer;
  // Centre pixel (32, 32) sees the plane at the view axis, from 5 units up.
  const std::size_t c = 32 * 64 + 32;
  EXPECT_NEAR(gb.plane("depth.Z")[c], 5.0f, 1e-3f);
  EXPECT_NEAR(gb.plane("N.Y")[c], 1.0f, 1e-6f);
  EXPECT_NEAR(gb.plane("albedo.R")[c], 0.5f, 1e-6f);
  EXPECT_EQ(gb.uint_plane("id")[c], 1u);
  // Lambert + Blinn-Phong with roughness 1 (exponent clamped to 1), n.l = 1, n.h ~ 1:
  // E * (a / pi + 0.04 * (1 + 8) / (8 pi) * n.h).
  const float pi = 3.14159265f;
  const float expected = 2.0f * (0.5f / pi + 0.04f * 9.0f / (8.0f * pi));
  EXPECT_NEAR(ref.plane("direct.R")[c], expected, 2e-4f);
  EXPECT_NEAR(ref.plane("shadow.Y")[c], 1.0f, 1e-6f);   // nothing between the plane and the light
  EXPECT_NEAR(ref.plane("ssao.Y")[c], 1.0f, 1e-6f);     // a plane does not occlude itself
  EXPECT_NEAR(ref.plane("gi.R")[c], 0.0f, 1e-7f);       // VPLs on the same plane: cos theta_x = 0
  for (std::size_t i = 0; i < ref.pixel_count(); ++i) {
    const float sum = ref.plane("direct.R")[i] * ref.plane("shadow.Y")[i] + ref.plane("gi.R")[i] * ref.plane("ssao.Y")[i];
    ASSERT_NEAR(ref.plane("R")[i], sum, 1e-5f) << "pixel " << i;
  }
}

TEST(RenderPayload, SpotAndPointLightsFollowTheInverseSquareLaw) {
  PlaneScene scene(false);
  RenderOptions o = small_options(64, 64);
  o.outputs = RenderOutputs{false, false, true, false};
  o.reference_spp = 1;
  auto r = Renderer::create(o, scene.geometry());
  ASSERT_TRUE(r) << r.error().message;
  const float pi = 3.14159265f;
  const float brdf = 0.5f / pi + 0.04f * 9.0f / (8.0f * pi);  // n.l = n.h = 1 at the centre
  for (auto type : {LightState::Type::Spot, LightState::Type::Point}) {
    FrameState s = scene.state();
    LightState& l = s.lights[0];
    l.type = type;
    l.position = {0.0f, 2.0f, 0.0f};
    l.direction = {0.0f, -1.0f, 0.0f};
    l.intensity = 4.0f;  // candela: E = 4 / 2^2 = 1 lux at the centre, inside the inner cone
    l.inner_cone = 0.3f;
    l.outer_cone = 0.5f;
    FrameInput in;
    in.current = &s;
    auto out = r->render(in);
    ASSERT_TRUE(out) << out.error().message;
    const Image& ref = *out->reference;
    const std::size_t c = 32 * 64 + 32;
    EXPECT_NEAR(ref.plane("direct.G")[c], brdf, 2e-4f) << int(type);
    EXPECT_NEAR(ref.plane("shadow.Y")[c], 1.0f, 1e-6f) << int(type);
    // Outside the spot's outer cone (tan 0.5 * 2 = 1.09 units off-centre; the image edge is 1.28) it is dark.
    if (type == LightState::Type::Spot) EXPECT_EQ(ref.plane("direct.G")[32 * 64 + 1], 0.0f);
    else EXPECT_GT(ref.plane("direct.G")[32 * 64 + 1], 0.0f);
    for (std::size_t i = 0; i < ref.pixel_count(); ++i) ASSERT_TRUE(std::isfinite(ref.plane("R")[i]));
  }
}

TEST(RenderPayload, WallAddsIndirectLightAndOcclusionNearIt) {
  PlaneScene scene(true);
  RenderOptions o = small_options(64, 64);
  o.outputs = RenderOutputs{false, false, true, false};
  o.reference_spp = 1;
  o.payload.vpl_count = 500;
  auto out = render_still(o, scene.geometry(), scene.state());
  ASSERT_TRUE(out) << out.error().message;
  const Image& ref = *out->reference;
  // The wall at x = 1 is seen edge-on; floor pixels just left of it (x slightly < 1) get bounce light
  // and occlusion, pixels far left get less bounce and no occlusion.
  // Image x of world x: camera at height 5, yfov 0.5 -> half width tan(0.25) * 5 = 1.277 world units.
  auto px = [](float wx) { return int((wx / (std::tan(0.25f) * 5.0f) * 0.5f + 0.5f) * 64.0f); };
  const std::size_t near_wall = 32 * 64 + std::size_t(px(0.9f));
  const std::size_t far_wall = 32 * 64 + std::size_t(px(-1.0f));
  EXPECT_GT(ref.plane("gi.R")[near_wall], 0.0f);
  EXPECT_GT(ref.plane("gi.R")[near_wall], ref.plane("gi.R")[far_wall]);
  EXPECT_LT(ref.plane("ssao.Y")[near_wall], 0.95f);
  EXPECT_NEAR(ref.plane("ssao.Y")[far_wall], 1.0f, 1e-6f);
}

TEST(RenderPayload, ShadowUnderTheBox) {
  SyntheticScene scene;
  RenderOptions o = small_options(96, 72);
  o.outputs = RenderOutputs{true, false, true, false};
  o.reference_spp = 1;
  o.payload.shadow_map_size = 1024;
  auto out = render_still(o, scene.geometry(), scene.evaluate(0.0));
  ASSERT_TRUE(out) << out.error().message;
  // Fully shadowed and fully lit ground pixels both exist; shadow stays in [0, 1].
  const auto* id = out->gbuffer->uint_plane("id");
  const float* sh = out->reference->plane("shadow.Y");
  int dark = 0, lit = 0;
  for (std::size_t i = 0; i < out->reference->pixel_count(); ++i) {
    ASSERT_GE(sh[i], 0.0f);
    ASSERT_LE(sh[i], 1.0f);
    if (id[i] != 1) continue;
    dark += sh[i] < 0.05f;
    lit += sh[i] > 0.999f;
  }
  EXPECT_GT(dark, 20);
  EXPECT_GT(lit, 1000);
}

TEST(RenderOptionsTest, BadValuesAreUsageErrors) {
  SyntheticScene scene;
  RenderOptions o = small_options(64, 48);
  o.factor = 5;
  auto r = Renderer::create(o, scene.geometry());
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().kind, ErrorKind::Usage);
  o.factor = 4;
  o.shade_mip_bias = std::numeric_limits<float>::quiet_NaN();
  EXPECT_FALSE(Renderer::create(o, scene.geometry()));
  o.shade_mip_bias = 17.0f;
  EXPECT_FALSE(Renderer::create(o, scene.geometry()));
  EXPECT_FALSE(parse_payload_terms("direct,foo"));
  EXPECT_FALSE(RenderOutputs::parse(""));
  auto p = parse_payload_terms("ssao,gi");
  ASSERT_TRUE(p);
  EXPECT_EQ(p->channels(), (std::vector<std::string>{"R", "G", "B", "ssao.Y", "gi.R", "gi.G", "gi.B"}));
}

}  // namespace
}  // namespace temporal
