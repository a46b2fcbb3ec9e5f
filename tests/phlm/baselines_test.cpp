// TAA (Karis 2014), EMA (seed 003 eq. 1) and FXAA (Lottes 2011) on synthetic frames with hand-computed values.
#include "temporal/phlm/ema.h"
#include "temporal/phlm/fxaa.h"
#include "temporal/phlm/taa.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <functional>
#include <random>

namespace {

using namespace temporal;
const std::vector<std::string> kRgb = {"R", "G", "B"};

Image make_frame(int w, int h, const std::function<float(int, int, int)>& f) {
  Image img(w, h);
  for (int c = 0; c < 3; ++c) {
    float* p = img.add_channel(kRgb[std::size_t(c)]);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) p[std::size_t(y * w + x)] = f(x, y, c);
  }
  return img;
}

FilterInput input_for(const Image& img, bool reset = false) {
  FilterInput in;
  in.color = &img;
  in.channels = kRgb;
  in.reset = reset;
  return in;
}

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

TEST(Ema, FollowsEquationOne) {
  EmaFilter ema;  // alpha = 0.9
  Image out;
  ASSERT_TRUE(ema.process(input_for(make_frame(3, 3, [](int, int, int) { return 1.0f; })), out));
  ASSERT_TRUE(ema.process(input_for(make_frame(3, 3, [](int, int, int) { return 0.0f; })), out));
  EXPECT_NEAR(out.plane("R")[4], 0.9f, 1e-6f);  // 0.9 * 1 + 0.1 * 0
  ASSERT_TRUE(ema.process(input_for(make_frame(3, 3, [](int, int, int) { return 0.0f; })), out));
  EXPECT_NEAR(out.plane("R")[4], 0.81f, 1e-6f);
}

TEST(Ema, RejectsHistoryOnIdOrDepthChange) {
  EmaFilter ema;
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
