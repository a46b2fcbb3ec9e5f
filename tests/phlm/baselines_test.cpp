// TAA (Karis 2014), EMA (seed 003 eq. 1) and FXAA (Lottes 2011) on synthetic frames with hand-computed values.
#include "temporal/phlm/ema.h"
#include "temporal/phlm/fxaa.h"
#include "temporal/phlm/taa.h"

#include "filter_frames.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <functional>
#include <random>

namespace {

using namespace temporal;
using namespace temporal::phlm;
using namespace temporal::phlm::test_frames;

TEST(Taa, ConstantColourIsAFixedPoint) {
  TaaFilter taa;
  Image out;
  const Image frame = make_frame(6, 6, [](int, int, int c) { return 0.1f + 0.3f * float(c); });
  for (int t = 0; t < 50; ++t) {
    FilterInput in = input_for(frame);
    in.jitter = {0.3f * std::sin(float(t)), -0.2f};  // a jitter changes nothing on a constant image
    ASSERT_TRUE(taa.process(in, out));
  }
  for (int c = 0; c < 3; ++c)
    for (std::size_t i = 0; i < out.pixel_count(); ++i) EXPECT_NEAR(out.plane(kRgb[std::size_t(c)])[i], 0.1f + 0.3f * float(c), 1e-6f);
}

TEST(Taa, FirstFrameIsTheJitterCompensatedFilterOfTheInput) {
  // One bright pixel, no jitter: the centre weight is 1, the 4-neighbours exp(-2.29), the corners exp(-4.58).
  const Image frame = make_frame(5, 5, [](int x, int y, int) { return (x == 2 && y == 2) ? 1.0f : 0.0f; });
  TaaFilter taa;
  Image out;
  ASSERT_TRUE(taa.process(input_for(frame), out));
  const double w1 = std::exp(-2.29), w2 = std::exp(-4.58), sum = 1.0 + 4.0 * w1 + 4.0 * w2;
  EXPECT_NEAR(out.plane("R")[12], 1.0 / sum, 1e-6);
  EXPECT_NEAR(out.plane("R")[7], w1 / sum, 1e-6);
  EXPECT_NEAR(out.plane("R")[6], w2 / sum, 1e-6);
}

TEST(Taa, JitterMovesTheReconstructionWeights) {
  // The sample of neighbour (dx, dy) was taken at (dx + jx, dy + jy) from the pixel centre (conventions).
  const Image frame = make_frame(5, 5, [](int x, int y, int) { return (x == 2 && y == 2) ? 1.0f : 0.0f; });
  TaaFilter taa;
  Image out;
  FilterInput in = input_for(frame);
  in.jitter = {0.3f, -0.2f};
  ASSERT_TRUE(taa.process(in, out));
  auto weight = [](double dx, double dy) { return std::exp(-2.29 * ((dx + 0.3) * (dx + 0.3) + (dy - 0.2) * (dy - 0.2))); };
  double sum = 0.0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) sum += weight(dx, dy);
  EXPECT_NEAR(out.plane("R")[12], weight(0, 0) / sum, 1e-6);
  EXPECT_NEAR(out.plane("R")[11], weight(1, 0) / sum, 1e-6);   // pixel (1,2): the bright sample is at dx = +1
  EXPECT_NEAR(out.plane("R")[13], weight(-1, 0) / sum, 1e-6);  // pixel (3,2): at dx = -1
}

TEST(Taa, ReducesTemporalNoiseAndClipsStaleHistory) {
  std::mt19937 rng(11);
  std::normal_distribution<float> noise(0.0f, 0.1f);
  TaaFilter taa;
  Image out;
  double var_out = 0.0;
  int n = 0;
  for (int t = 0; t < 400; ++t) {
    Image frame = make_frame(8, 8, [&](int, int, int) { return 0.5f + noise(rng); });
    ASSERT_TRUE(taa.process(input_for(frame), out));
    if (t >= 200) {
      var_out += std::pow(out.plane("G")[27] - 0.5, 2.0);
      ++n;
    }
  }
  EXPECT_LT(std::sqrt(var_out / n), 0.05);  // input sigma 0.1
  // A new colour far from the history: the history is clipped into the new box, so the output jumps there.
  Image red = make_frame(8, 8, [](int, int, int c) { return c == 0 ? 1.0f : 0.0f; });
  FilterStats stats;
  ASSERT_TRUE(taa.process(input_for(red), out, &stats));
  EXPECT_EQ(stats.clamped, 64u);
  EXPECT_NEAR(out.plane("R")[27], 1.0f, 1e-5f);
  EXPECT_NEAR(out.plane("G")[27], 0.0f, 1e-5f);
}

// Issue 16: TAA's velocity dilation takes the motion of the closest surface of the 3x3 neighbourhood (UE4).
// A foreground block (x >= 5, depth 2) moves with motion (-1, 0); the background is static at depth 10 except a
// far plane strip (x <= 1, depth 50) with a larger motion (-2, 0), so the dilation must pick by depth, not by
// the size of the motion.
TEST(Taa, VelocityDilationPicksTheClosestSurface) {
  const int w = 10, h = 5;
  Image g(w, h);
  float* mx = g.add_channel("motion.X", 0.0f);
  float* my = g.add_channel("motion.Y", 0.0f);
  float* depth = g.add_channel("depth.Z", 10.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = std::size_t(y * w + x);
      if (x >= 5) {
        depth[i] = 2.0f;
        mx[i] = -1.0f;
      } else if (x <= 1) {
        depth[i] = 50.0f;
        mx[i] = -2.0f;
      }
    }
  // The image is a grey ramp 0.1 x, the same in both frames, so every history value is known: the first frame's
  // output at interior pixels is the ramp itself (symmetric reconstruction weights of a linear function).
  const Image ramp = make_frame(w, h, [](int x, int, int) { return 0.1f * float(x); });
  for (const char* velocity : {"nearest", "centre"}) {
    TaaParams p;
    p.alpha = 0.0f;  // the output is the (clipped) history alone
    p.clip = "minmax";
    p.velocity = velocity;
    TaaFilter taa(p);
    Image out;
    FilterInput in = input_for(ramp);
    in.motion_x = mx;
    in.motion_y = my;
    in.depth = depth;
    in.debug = true;
    ASSERT_TRUE(taa.process(in, out));
    ASSERT_TRUE(taa.process(in, out));
    const float* vx = out.plane("debug.velocity.X");
    const float* r = out.plane("R");
    const bool nearest = std::string(velocity) == "nearest";
    const int y = 2;
    auto at = [&](int x) { return std::size_t(y * w + x); };
    // Pixel 4: background (depth 10, motion 0) beside the foreground block: the closest surface of its 3x3
    // neighbourhood is the block (depth 2), so it takes the block's motion -1 and fetches the history at x = 3,
    // 0.3 (inside its box [0.3, 0.5]).
    EXPECT_EQ(vx[at(4)], nearest ? -1.0f : 0.0f) << velocity;
    EXPECT_NEAR(r[at(4)], nearest ? 0.3f : 0.4f, 1e-6f) << velocity;
    // Pixel 3: neighbours 2..4 all at depth 10; ties go to the centre: its own motion 0.
    EXPECT_EQ(vx[at(3)], 0.0f) << velocity;
    EXPECT_NEAR(r[at(3)], 0.3f, 1e-6f) << velocity;
    // Pixel 2: beside the far strip (pixel 1, depth 50, the larger motion -2): the closest surface is its own
    // (depth 10, motion 0); the dilation picks by depth, not by the size of the motion.
    EXPECT_EQ(vx[at(2)], 0.0f) << velocity;
    // Pixel 1 (far strip, motion -2): beside the depth-10 background at pixel 2, it takes motion 0 when dilated.
    EXPECT_EQ(vx[at(1)], nearest ? 0.0f : -2.0f) << velocity;
    // Pixel 6 is inside the block: its own motion.
    EXPECT_EQ(vx[at(6)], -1.0f) << velocity;
  }
}

TEST(Taa, NearestVelocityNeedsDepthWhenThereIsMotion) {
  const Image frame = make_frame(4, 4, [](int, int, int) { return 0.5f; });
  Image g(4, 4);
  FilterInput in = input_for(frame);
  in.motion_x = g.add_channel("motion.X", 0.0f);
  in.motion_y = g.add_channel("motion.Y", 0.0f);
  TaaFilter taa;  // velocity = nearest
  Image out;
  const Status s = taa.process(in, out);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().kind, ErrorKind::Usage);
  EXPECT_NE(s.error().message.find("--taa-velocity centre"), std::string::npos) << s.error().message;
  TaaParams centre;
  centre.velocity = "centre";
  TaaFilter taa_centre(centre);
  EXPECT_TRUE(taa_centre.process(in, out));
  TaaParams bad;
  bad.clip = "aabb";
  TaaFilter taa_bad(bad);
  EXPECT_FALSE(taa_bad.process(input_for(frame), out));
}

// Salvi 2016's variance clipping: the box is mu +- gamma sigma of the 3x3 samples in YCoCg and the history is
// clipped towards mu. Grey 3x3 frame: eight samples 0.2 and a centre 0.5 -> mu = 2.1 / 9, E[v^2] = 0.57 / 9,
// sigma = sqrt(0.57 / 9 - (2.1 / 9)^2) = 0.0942809; a history of 1.0 is clipped to mu + sigma.
TEST(Taa, VarianceClippingUsesTheMeanAndStandardDeviation) {
  const Image one = make_frame(3, 3, [](int, int, int) { return 1.0f; });
  const Image spot = make_frame(3, 3, [](int x, int y, int) { return (x == 1 && y == 1) ? 0.5f : 0.2f; });
  TaaParams p;
  p.alpha = 0.0f;
  p.clip = "variance";
  TaaFilter taa(p);
  Image out;
  ASSERT_TRUE(taa.process(input_for(one), out));
  FilterStats stats;
  ASSERT_TRUE(taa.process(input_for(spot), out, &stats));
  const double mu = 2.1 / 9.0, sigma = std::sqrt(0.57 / 9.0 - mu * mu);
  EXPECT_NEAR(out.plane("R")[4], mu + sigma, 1e-6);
  EXPECT_EQ(stats.clamped, 9u);
  // gamma = 2 widens the box: mu + 2 sigma.
  p.gamma = 2.0f;
  TaaFilter wide(p);
  ASSERT_TRUE(wide.process(input_for(one), out));
  ASSERT_TRUE(wide.process(input_for(spot), out));
  EXPECT_NEAR(out.plane("R")[4], mu + 2.0 * sigma, 1e-6);
}

TEST(Taa, NonFiniteInputIsIgnored) {
  TaaFilter taa;
  Image out;
  Image frame = make_frame(4, 4, [](int, int, int) { return 0.5f; });
  ASSERT_TRUE(taa.process(input_for(frame), out));
  frame.plane("R")[5] = NAN;
  FilterStats stats;
  ASSERT_TRUE(taa.process(input_for(frame), out, &stats));
  EXPECT_EQ(stats.non_finite, 1u);
  for (const auto& c : kRgb)
    for (std::size_t i = 0; i < 16; ++i) EXPECT_NEAR(out.plane(c)[i], 0.5f, 1e-6f);
}

// TAA runs kLanes pixels of a row at once (taa_kernels.inc, lanes.inc): a pixel's result must not depend on the lane
// it falls in, nor on whether its vector is a whole one or the row's last, partial one. The same scene filtered at
// width 45 and with its first column cut off (every pixel one lane over; 45 = 5 x 8 + 5 and 44 = 5 x 8 + 4, or
// 11 x 4 + 1 and 11 x 4 in the 4-lane v2 copy) must give the same bits, except where the cut edge reaches: its
// clamped taps spread by the motion, the 3x3 box and the Catmull-Rom footprint, at most 3 px per frame here.
// Verified to fail when a lane reads its neighbour's column or the partial vector's lanes are mixed up.
// Noise, NaN samples, clipping, a foreground block for the nearest-depth velocity, every clip / history / velocity.
TEST(Taa, APixelsResultDoesNotDependOnItsLane) {
  const int w = 45, h = 11, frames = 4, margin = 3 * frames + 1;
  auto hash = [](int x, int y, int t, int c) {
    std::uint32_t v = std::uint32_t(x * 73856093) ^ std::uint32_t(y * 19349663) ^ std::uint32_t(t * 83492791) ^
                      std::uint32_t(c * 2654435761u);
    v ^= v >> 13;
    v *= 0x5bd1e995u;
    v ^= v >> 15;
    return float(v & 0xffff) / 65535.0f;
  };
  // Scene coordinates: pixel x of the cut frame is pixel x + 1 of the full one.
  auto colour = [&](int x, int y, int t, int c) {
    if ((x * 7 + y * 3 + t) % 23 == 0) return NAN;  // a sample the box and the blend must leave out
    return 0.2f + 0.5f * float((x / 4 + y / 3 + t) % 2) + 0.3f * hash(x, y, t, c);
  };
  // Motion in multiples of 1/256 px, so that x + motion is exact at either width (otherwise the fetch position
  // x + 1 + m and x + m round differently once x + 1 crosses a power of two: a different, not a wrong, value).
  auto q = [](float v) { return std::round(v * 256.0f) / 256.0f; };
  auto motion_x = [&](int x, int y, int t) { return x >= 20 && x < 30 ? -0.75f : q(0.45f * std::sin(0.4f * float(y + t))); };
  auto motion_y = [&](int x, int, int) { return q(0.3f * std::cos(0.3f * float(x))); };
  auto depth = [](int x, int y, int) { return x >= 20 && x < 30 ? 2.0f : 5.0f + 0.1f * float(x + y); };
  std::vector<TaaParams> options(4);
  options[1].clip = "minmax";
  options[1].velocity = "centre";
  options[2].history = "bilinear";
  options[2].gamma = 2.5f;
  options[3].history = "nearest";
  options[3].alpha = 0.1f;
  for (const TaaParams& p : options) {
    SCOPED_TRACE(::testing::Message() << p.clip << " " << p.history << " " << p.velocity);
    TaaFilter full(p), cut(p);
    Image out_full, out_cut;
    std::size_t clipped = 0;
    for (int t = 0; t < frames; ++t) {
      Image frames_of[2];
      Image gbuffers[2];
      Image* outs[2] = {&out_full, &out_cut};
      TaaFilter* filters[2] = {&full, &cut};
      for (int k = 0; k < 2; ++k) {
        const int fw = w - k;
        frames_of[k] = make_frame(fw, h, [&](int x, int y, int c) { return colour(x + k, y, t, c); });
        gbuffers[k] = Image(fw, h);
        float* mx = gbuffers[k].add_channel("motion.X");
        float* my = gbuffers[k].add_channel("motion.Y");
        float* z = gbuffers[k].add_channel("depth.Z");
        for (int y = 0; y < h; ++y)
          for (int x = 0; x < fw; ++x) {
            const std::size_t i = std::size_t(y * fw + x);
            mx[i] = motion_x(x + k, y, t);
            my[i] = motion_y(x + k, y, t);
            z[i] = depth(x + k, y, t);
          }
        FilterInput in = input_for(frames_of[k]);
        in.motion_x = mx;
        in.motion_y = my;
        in.depth = z;
        in.jitter = {0.25f * float(t % 2) - 0.125f, 0.2f - 0.1f * float(t)};
        in.debug = true;
        FilterStats stats;
        ASSERT_TRUE(filters[k]->process(in, *outs[k], &stats));
        if (k == 0) clipped += stats.clamped;
      }
      for (const char* c : {"R", "G", "B", "debug.clip", "debug.noHistory", "debug.velocity.X"}) {
        const float* a = out_full.plane(c);
        const float* b = out_cut.plane(c);
        ASSERT_NE(a, nullptr) << c;
        ASSERT_NE(b, nullptr) << c;
        int mismatches = 0;
        for (int y = 0; y < h; ++y)
          for (int x = margin; x < w; ++x) {
            const float va = a[y * w + x], vb = b[y * (w - 1) + x - 1];
            if (std::memcmp(&va, &vb, sizeof va) != 0 && mismatches++ < 3)
              ADD_FAILURE() << c << " frame " << t << " pixel (" << x << ", " << y << "): " << va << " against " << vb;
          }
        EXPECT_EQ(mismatches, 0) << c << " frame " << t;
      }
    }
    EXPECT_GT(clipped, 0u);  // the box test ran its clipping side
  }
}

TEST(Ema, FollowsEquationOne) {
  EmaParams params;
  params.alpha = 0.9f;  // eq. 1 by hand with a ten-frame memory (the default is the tuned 0.5)
  EmaFilter ema(params);
  Image out;
  ASSERT_TRUE(ema.process(input_for(make_frame(3, 3, [](int, int, int) { return 1.0f; })), out));
  ASSERT_TRUE(ema.process(input_for(make_frame(3, 3, [](int, int, int) { return 0.0f; })), out));
  EXPECT_NEAR(out.plane("R")[4], 0.9f, 1e-6f);  // 0.9 * 1 + 0.1 * 0
  ASSERT_TRUE(ema.process(input_for(make_frame(3, 3, [](int, int, int) { return 0.0f; })), out));
  EXPECT_NEAR(out.plane("R")[4], 0.81f, 1e-6f);
}

TEST(Ema, RejectsHistoryOnIdOrDepthChange) {
  EmaParams params;
  params.alpha = 0.9f;
  EmaFilter ema(params);
  Image out;
  Image g(3, 1);
  float* depth = g.add_channel("depth.Z", 5.0f);
  std::uint32_t* id = g.add_uint_channel("id", 1);
  const Image one = make_frame(3, 1, [](int, int, int) { return 1.0f; });
  const Image zero = make_frame(3, 1, [](int, int, int) { return 0.0f; });
  FilterInput in = input_for(one);
  in.depth = depth;
  in.id = id;
  ASSERT_TRUE(ema.process(in, out));
  id[0] = 2;        // pixel 0: another surface
  depth[1] = 6.0f;  // pixel 1: 20% deeper
  in.color = &zero;
  FilterStats stats;
  ASSERT_TRUE(ema.process(in, out, &stats));
  EXPECT_EQ(stats.history_resets, 2u);
  EXPECT_EQ(out.plane("R")[0], 0.0f);
  EXPECT_EQ(out.plane("R")[1], 0.0f);
  EXPECT_NEAR(out.plane("R")[2], 0.9f, 1e-6f);
}

TEST(Fxaa, FlatRegionsAreUntouchedAndStaircasesSmoothed) {
  // A 45-degree-ish staircase edge between black and white.
  const Image frame = make_frame(16, 16, [](int x, int y, int) { return (x > y / 2 + 4) ? 1.0f : 0.0f; });
  Image out;
  FilterStats stats;
  ASSERT_TRUE(fxaa(input_for(frame), out, {}, &stats));
  EXPECT_GT(stats.clamped, 0u);
  int blended = 0;
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      const float v = out.plane("G")[std::size_t(y * 16 + x)];
      ASSERT_GE(v, 0.0f);
      ASSERT_LE(v, 1.0f);
      if (v > 0.01f && v < 0.99f) ++blended;
      if (std::abs(x - (y / 2 + 4)) > 3) {
        EXPECT_EQ(v, frame.plane("G")[std::size_t(y * 16 + x)]);
      }
    }
  EXPECT_GE(blended, 16);  // at least one blended pixel per row along the edge
}

TEST(Fxaa, ConstantPassesThroughAndNonFinitePixelsAreFilledFromNeighbours) {
  Image frame = make_frame(6, 6, [](int x, int, int) { return 0.1f * float(x); });
  frame.plane("B")[8] = NAN;                        // pixel (2, 1): neighbours x = 1, 3 (0.1, 0.3) and (2, 0), (2, 2) (0.2)
  frame.plane("R")[0] = std::numeric_limits<float>::infinity();  // corner (0, 0): neighbours (1, 0) = 0.1, (0, 1) = 0
  Image out;
  FilterStats stats;
  ASSERT_TRUE(fxaa(input_for(frame), out, {}, &stats));
  EXPECT_EQ(stats.non_finite, 2u);
  for (const char* c : {"R", "G", "B"})
    for (std::size_t i = 0; i < out.pixel_count(); ++i) EXPECT_TRUE(std::isfinite(out.plane(c)[i])) << c << i;
  EXPECT_FLOAT_EQ(out.plane("B")[8], (0.1f + 0.3f + 0.2f + 0.2f) / 4.0f);  // the pixel's other channels are the same
  EXPECT_FLOAT_EQ(out.plane("R")[0], 0.05f);
  Image flat = make_frame(6, 6, [](int, int, int) { return 0.3f; });
  ASSERT_TRUE(fxaa(input_for(flat), out, {}, &stats));
  EXPECT_EQ(out.plane("R")[20], 0.3f);  // no contrast: unchanged
}

}  // namespace
