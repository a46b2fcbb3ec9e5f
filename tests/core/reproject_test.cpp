// The reprojection module (temporal/core/reproject.h): the one off-screen rule, the bilinear taps, the
// disocclusion test and the row kernel, on hand-made images with hand-computed values.
#include "temporal/core/reproject.h"

#include "temporal/core/isa.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

namespace rp = temporal::reproject;

TEST(Reproject, OffScreenRuleIsThePixelArea) {
  // Pixel-index coordinates: the centre of pixel 0 is 0, the image area is [-0.5, W - 0.5).
  EXPECT_TRUE(rp::on_screen(-0.5f, 0.0f, 4, 3));
  EXPECT_FALSE(rp::on_screen(-0.5001f, 0.0f, 4, 3));
  EXPECT_TRUE(rp::on_screen(3.499f, 2.499f, 4, 3));
  EXPECT_FALSE(rp::on_screen(3.5f, 0.0f, 4, 3));
  EXPECT_FALSE(rp::on_screen(0.0f, 2.5f, 4, 3));
  EXPECT_FALSE(rp::on_screen(NAN, 0.0f, 4, 3));
}

TEST(Reproject, BilinearWeightsAndEdgeRepeat) {
  const auto b = rp::bilinear(1.25f, 0.5f, 4, 3);  // taps (1,0) (2,0) (1,1) (2,1)
  EXPECT_EQ(b.i00, 1u);
  EXPECT_EQ(b.i10, 2u);
  EXPECT_EQ(b.i01, 5u);
  EXPECT_EQ(b.i11, 6u);
  EXPECT_FLOAT_EQ(b.w00, 0.75f * 0.5f);
  EXPECT_FLOAT_EQ(b.w10, 0.25f * 0.5f);
  EXPECT_FLOAT_EQ(b.w01, 0.75f * 0.5f);
  EXPECT_FLOAT_EQ(b.w11, 0.25f * 0.5f);
  const float plane[] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11};
  EXPECT_FLOAT_EQ(b(plane), 3.25f);  // x 1.25 + 4 * y 0.5
  // Half a pixel outside the left edge: the outside taps repeat column 0.
  EXPECT_FLOAT_EQ(rp::bilinear(-0.4f, 1.0f, 4, 3)(plane), 4.0f);
  // Exactly at a centre: that pixel, bit for bit.
  EXPECT_EQ(rp::bilinear(2.0f, 2.0f, 4, 3)(plane), 10.0f);
}

TEST(Reproject, CatmullRomWeightsSumToOneAndInterpolate) {
  float w[4];
  rp::catmull_rom_weights(0.0f, w);
  EXPECT_FLOAT_EQ(w[0], 0.0f);
  EXPECT_FLOAT_EQ(w[1], 1.0f);
  rp::catmull_rom_weights(0.5f, w);
  EXPECT_FLOAT_EQ(w[0], -0.0625f);
  EXPECT_FLOAT_EQ(w[1], 0.5625f);
  EXPECT_FLOAT_EQ(w[0] + w[1] + w[2] + w[3], 1.0f);
}

TEST(Reproject, SameSurfaceIsRelativeToTheLargerDepth) {
  const rp::SurfaceTest t;  // 5 %, ids compared
  EXPECT_TRUE(rp::same_surface(10.0f, 3, 10.4f, 3, t));   // 0.4 / 10.4 = 3.8 %
  EXPECT_FALSE(rp::same_surface(10.0f, 3, 10.6f, 3, t));  // 0.6 / 10.6 = 5.7 %
  EXPECT_FALSE(rp::same_surface(10.0f, 3, 10.0f, 4, t));  // contact point: another material
  EXPECT_TRUE(rp::same_surface(10.0f, 3, 10.0f, 4, rp::SurfaceTest{0.05f, false}));
}

namespace {

// The kernel copies this CPU runs (v2 first), or the one active copy in a build with one copy (TEMPORAL_NATIVE): the
// levels at which the row kernels' tests compare paths bit for bit.
std::vector<temporal::isa::Level> levels_here() {
  namespace isa = temporal::isa;
  std::vector<isa::Level> levels;
  for (const isa::Level l : {isa::Level::V2, isa::Level::V3, isa::Level::V4})
    if (isa::supported(l)) levels.push_back(l);
  if (levels.empty()) levels.push_back(isa::active());
  return levels;
}

// A 6x4 previous frame: depth 10 on the left half (id 1), 20 on the right half (id 2); values = x + 10 y.
struct Prev {
  int w = 6, h = 4;
  std::vector<float> z, value;
  std::vector<std::uint32_t> id;
  Prev() {
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        z.push_back(x < 3 ? 10.0f : 20.0f);
        id.push_back(x < 3 ? 1u : 2u);
        value.push_back(float(x + 10 * y));
      }
  }
};
}  // namespace

TEST(Reproject, RowKernelDropsTheTapsOfAnotherSurface) {
  Prev p;
  // Current frame: every pixel moved half a pixel right (motion -0.5: it came from x - 0.5), all at depth 10.
  std::vector<float> mx(24, -0.5f), my(24, 0.0f), z(24, 10.0f);
  std::vector<std::uint32_t> id(24, 1u);
  rp::Frames fr{p.w, p.h, mx.data(), my.data(), z.data(), id.data(), p.z.data(), p.id.data(), {}};
  rp::HistoryRow h;
  rp::reproject_row(fr, 1, h);
  std::vector<float> out(6);
  const float* prev[] = {p.value.data()};
  float* o[] = {out.data()};
  rp::gather_row(h, prev, o, 1, p.w);
  // x = 2: taps (1,1) and (2,1), both the near surface: (11 + 12) / 2.
  EXPECT_EQ(h.hit[2], 1.0f);
  EXPECT_FLOAT_EQ(out[2], 11.5f);
  // x = 3: taps (2,1) near and (3,1) far: the far tap is dropped, the near one renormalised to weight 1.
  EXPECT_EQ(h.hit[3], 1.0f);
  EXPECT_FLOAT_EQ(out[3], 12.0f);
  // x = 5: taps (4,1), (5,1): both far (depth 20 vs 10: 50 % > 5 %, and another id): disoccluded.
  EXPECT_EQ(h.hit[5], 0.0f);
  EXPECT_EQ(out[5], 0.0f);
  // x = 0: position -0.5 is on the edge of the area: the outside tap is dropped, pixel 0 kept.
  EXPECT_EQ(h.hit[0], 1.0f);
  EXPECT_FLOAT_EQ(out[0], 10.0f);
}

TEST(Reproject, RowKernelOffScreenAndNonFiniteMotionMiss) {
  Prev p;
  std::vector<float> mx(24, -0.6f), my(24, 0.0f);
  mx[6 + 3] = NAN;
  mx[6 + 4] = 1e30f;
  rp::Frames fr{p.w, p.h, mx.data(), my.data(), nullptr, nullptr, nullptr, nullptr, {}};  // no depth: area rule only
  rp::HistoryRow h;
  rp::reproject_row(fr, 1, h);
  EXPECT_EQ(h.hit[0], 0.0f);  // position -0.6: outside the image area
  EXPECT_EQ(h.hit[1], 1.0f);
  EXPECT_EQ(h.hit[3], 0.0f);  // NaN motion
  EXPECT_EQ(h.hit[4], 0.0f);  // absurd motion
  EXPECT_EQ(h.hit[5], 1.0f);  // no depth: the far surface is not tested
}

TEST(Reproject, WarpPlanesIsNaNWhereTheFetchMisses) {
  Prev p;
  std::vector<float> mx(24, 0.0f), my(24, -1.0f), z(24, 10.0f), out(24);
  std::vector<std::uint32_t> id(24, 1u);
  rp::Frames fr{p.w, p.h, mx.data(), my.data(), z.data(), id.data(), p.z.data(), p.id.data(), {}};
  const float* prev[] = {p.value.data()};
  float* o[] = {out.data()};
  rp::warp_planes(fr, prev, o);
  EXPECT_TRUE(std::isnan(out[0]));   // row 0 came from row -1: off screen
  EXPECT_FLOAT_EQ(out[6 + 1], 1.0f);  // (1, 1) came from (1, 0)
  EXPECT_TRUE(std::isnan(out[6 + 4]));  // the right half is another surface
  // Without motion and geometry the warp is the identity.
  rp::Frames still{p.w, p.h, nullptr, nullptr, nullptr, nullptr, nullptr, nullptr, {}};
  rp::warp_planes(still, prev, o);
  for (int i = 0; i < 24; ++i) EXPECT_EQ(out[i], p.value[i]);
}

// Seed 000 section 3.2's warped depth: z_exp is the depth the current pixel's surface point had in the previous
// frame (G-buffer prevDepth.Z), compared at kWarpedDepthTolerance. A surface approaching the camera by 10 % per
// frame keeps its history with it and loses it with the current depth; a real disocclusion is a miss either way.
TEST(Reproject, WarpedDepthKeepsAnApproachingSurfaceAndStillFindsDisocclusions) {
  // Previous frame: 6x4, depth 10 on the left half (id 1, the approaching surface), 20 on the right (id 2).
  Prev p;
  // Current frame, no motion in the image: the left half is now at depth 9 (10 % nearer; it was at 10), the right
  // half shows the background at 50 (the far surface of the previous frame moved away: uncovered, id 2 kept so
  // that only depth decides). Warped depth: 10 on the left (where it was), 50 on the right (the background did
  // not move).
  std::vector<float> mx(24, 0.0f), my(24, 0.0f), z(24), zw(24);
  std::vector<std::uint32_t> id(24);
  for (int x = 0; x < 6; ++x)
    for (int y = 0; y < 4; ++y) {
      const int i = y * 6 + x;
      z[i] = x < 3 ? 9.0f : 50.0f;
      zw[i] = x < 3 ? 10.0f : 50.0f;
      id[i] = x < 3 ? 1u : 2u;
    }
  rp::HistoryRow h;
  // Current depth at 5 %: |9 - 10| / 10 = 10 % -> the approaching surface is a miss; the background too.
  rp::Frames cur{p.w, p.h, mx.data(), my.data(), z.data(), id.data(), p.z.data(), p.id.data(), {}};
  rp::reproject_row(cur, 1, h);
  for (int x = 0; x < 6; ++x) EXPECT_EQ(h.hit[x], 0.0f) << x;
  // Warped depth at the tight tolerance: |10 - 10| = 0 -> hit (weight 1 on its own pixel); 50 vs 20 -> miss.
  rp::Frames warped{p.w, p.h, mx.data(), my.data(), zw.data(), id.data(), p.z.data(), p.id.data(),
                    {rp::kWarpedDepthTolerance, true}};
  rp::reproject_row(warped, 1, h);
  for (int x = 0; x < 3; ++x) EXPECT_EQ(h.hit[x], 1.0f) << x;
  for (int x = 3; x < 6; ++x) EXPECT_EQ(h.hit[x], 0.0f) << x;
  // The tight tolerance is relative: 10 vs 10 * (1 + tol) still passes, 10 * (1 + 2 tol) does not.
  const rp::SurfaceTest t{rp::kWarpedDepthTolerance, true};
  EXPECT_TRUE(rp::same_surface(10.0f, 1, 10.0f * (1.0f + 0.99f * rp::kWarpedDepthTolerance), 1, t));
  EXPECT_FALSE(rp::same_surface(10.0f, 1, 10.0f * (1.0f + 2.0f * rp::kWarpedDepthTolerance), 1, t));
}

// reproject_gather_row (the taps' test and the gather in one loop on aligned runs) against reproject_row then
// gather_row, bit for bit, at every instruction-set level this CPU runs: hit flags and gathered values for 1 to 5
// planes (5: the two-step fallback) and the four depth / id settings, on a row mixing a pan (aligned runs of 16
// pixels and more), per-pixel motion (gather runs), NaN and off-screen motion, and depth and id edges.
TEST(Reproject, GatherRowInOnePassEqualsTheTwoSteps) {
  namespace isa = temporal::isa;
  const int W = 96, H = 24;
  const std::size_t N = std::size_t(W) * H;
  std::vector<float> mx(N), my(N), z(N), pz(N);
  std::vector<std::uint32_t> id(N), pid(N);
  std::vector<std::vector<float>> planes(5, std::vector<float>(N));
  std::uint32_t seed = 12345;
  auto rnd = [&seed] {  // [0, 1), deterministic
    seed = seed * 1664525u + 1013904223u;
    return float(seed >> 8) / float(1u << 24);
  };
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const std::size_t i = std::size_t(y) * W + x;
      if (x < 40) {  // a pan: one offset, aligned
        mx[i] = 1.25f;
        my[i] = -0.5f;
      } else if (x < 70) {  // per-pixel motion: gather runs
        mx[i] = 6.0f * rnd() - 3.0f;
        my[i] = 4.0f * rnd() - 2.0f;
      } else {  // a still region with a few non-finite or off-screen motions
        mx[i] = x % 11 == 0 ? NAN : (x % 13 == 0 ? 1e7f : 0.0f);
        my[i] = x % 17 == 0 ? float(H) : 0.0f;
      }
      z[i] = 10.0f + (x > 60 ? 5.0f : 0.0f) + 0.01f * rnd();
      pz[i] = 10.0f + (x > 58 ? 5.0f : 0.0f) + 0.01f * rnd();
      id[i] = x > 80 ? 2u : 1u;
      pid[i] = x > 82 ? 2u : 1u;
      for (auto& p : planes) p[i] = rnd();
    }
  for (const isa::Level level : levels_here()) {
    isa::ScopedLevel scoped(level);
    for (int mode = 0; mode < 4; ++mode) {
      rp::Frames fr;
      fr.width = W;
      fr.height = H;
      fr.motion_x = mx.data();
      fr.motion_y = my.data();
      if (mode & 1) {
        fr.z = z.data();
        fr.prev_z = pz.data();
      }
      if (mode & 2) {
        fr.id = id.data();
        fr.prev_id = pid.data();
      }
      for (int n = 1; n <= 5; ++n) {
        const float* prev[5];
        for (int i = 0; i < 5; ++i) prev[i] = planes[std::size_t(i)].data();
        std::vector<float> a(std::size_t(n) * W), b(std::size_t(n) * W);
        float* oa[5];
        float* ob[5];
        for (int i = 0; i < n; ++i) {
          oa[i] = a.data() + std::size_t(i) * W;
          ob[i] = b.data() + std::size_t(i) * W;
        }
        rp::HistoryRow ha, hb;
        bool gather_run = false, aligned_run = false;
        for (int y = 0; y < H; ++y) {
          rp::reproject_row(fr, y, ha);
          rp::gather_row(ha, prev, oa, n, W);
          rp::reproject_gather_row(fr, y, hb, prev, ob, n);
          for (const auto& sg : hb.segments) (sg.base >= 0 ? aligned_run : gather_run) = true;
          for (int x = 0; x < W; ++x) {
            ASSERT_EQ(ha.hit[x], hb.hit[x]) << isa::name(level) << " mode " << mode << " n " << n << " y " << y
                                            << " x " << x;
            for (int i = 0; i < n; ++i)
              ASSERT_EQ(oa[i][x], ob[i][x]) << isa::name(level) << " mode " << mode << " n " << n << " plane " << i
                                            << " y " << y << " x " << x;
          }
        }
        EXPECT_TRUE(aligned_run && gather_run);  // both kinds of run were exercised
      }
    }
  }
}

// reproject_gather_row finds its aligned runs 16 pixels at a time (reproject_kernels.inc, block_segments; in the v3
// and v4 copies one vector at a time, verified_runs) and extends them pixel by pixel at their ends: a run that
// starts inside a block after per-pixel motion keeps its first pixels, and a run whose offset is negative (motion
// to the left on the top row: base = x0 - X < 0) is gathered.
// The segments are checked, and the values against reproject_row then gather_row, bit for bit.
TEST(Reproject, GatherRowRunsStartInsideABlockAndNegativeOffsetsGather) {
  namespace isa = temporal::isa;
  const int W = 80, H = 6, X0 = 20;  // the pan starts at column 20, inside the block [16, 32)
  const std::size_t N = std::size_t(W) * H;
  std::vector<float> mx(N), my(N), z(N, 10.0f), pz(N, 10.0f);
  std::vector<std::vector<float>> planes(4, std::vector<float>(N));
  std::uint32_t seed = 777;
  auto rnd = [&seed] {
    seed = seed * 1664525u + 1013904223u;
    return float(seed >> 8) / float(1u << 24);
  };
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const std::size_t i = std::size_t(y) * W + x;
      mx[i] = x < X0 ? 6.0f * rnd() - 3.0f : -2.0f;  // x0 = X - 2 on the pan: aligned, offset y W - 2
      // y0 = y - 1 left of the pan (never the pan's offset, and off the image on row 0), y0 = y on it
      my[i] = x < X0 ? -0.5f - 0.5f * rnd() : 0.25f;
      for (auto& p : planes) p[i] = rnd();
    }
  for (const isa::Level level : levels_here()) {
    isa::ScopedLevel scoped(level);
    rp::Frames fr;
    fr.width = W;
    fr.height = H;
    fr.motion_x = mx.data();
    fr.motion_y = my.data();
    fr.z = z.data();
    fr.prev_z = pz.data();
    const float* prev[4] = {planes[0].data(), planes[1].data(), planes[2].data(), planes[3].data()};
    std::vector<float> a(4 * std::size_t(W)), b(4 * std::size_t(W));
    float* oa[4];
    float* ob[4];
    for (int i = 0; i < 4; ++i) {
      oa[i] = a.data() + std::size_t(i) * W;
      ob[i] = b.data() + std::size_t(i) * W;
    }
    for (int y = 0; y < H - 1; ++y) {  // the last row's taps leave the image (y0 + 1 = H): no aligned run there
      rp::HistoryRow ha, hb;
      rp::reproject_row(fr, y, ha);
      rp::gather_row(ha, prev, oa, 4, W);
      rp::reproject_gather_row(fr, y, hb, prev, ob, 4);
      std::vector<rp::HistoryRow::Segment> aligned;
      for (const auto& sg : hb.segments)
        if (sg.base >= 0) aligned.push_back(sg);
      if (y == 0) {
        EXPECT_TRUE(aligned.empty()) << isa::name(level);  // offset -2: gathered
      } else {
        ASSERT_EQ(aligned.size(), 1u) << isa::name(level) << " y " << y;
        EXPECT_EQ(aligned[0].x0, X0) << isa::name(level) << " y " << y;
        EXPECT_EQ(aligned[0].x1, W) << isa::name(level) << " y " << y;
        EXPECT_EQ(aligned[0].base, y * W - 2) << isa::name(level) << " y " << y;
      }
      for (int x = 0; x < W; ++x) {
        ASSERT_EQ(ha.hit[x], hb.hit[x]) << isa::name(level) << " y " << y << " x " << x;
        for (int i = 0; i < 4; ++i)
          ASSERT_EQ(oa[i][x], ob[i][x]) << isa::name(level) << " y " << y << " plane " << i << " x " << x;
      }
    }
  }
}
