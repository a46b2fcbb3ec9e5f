// High-frequency compensation (seed 004 section 5.1) and the eye-tracking limit (section 6).
#include "temporal/morph/grid_warp.h"
#include "temporal/morph/methods.h"
#include "temporal/morph/morph.h"

#include "synthetic.h"

#include <gtest/gtest.h>

#include <cmath>

namespace temporal::morph {
namespace {

TEST(MorphCompensation, GammaOneIsAPlainScalingByN) {
  for (float n : {2.0f, 3.0f, 4.0f})
    for (float low : {0.3f, 0.5f, 0.7f})  // L + N H >= 0: displayable
      for (float high : {-0.05f, 0.0f, 0.03f, 0.2f}) EXPECT_NEAR(compensated_high_frequency(high, low, n, 1.0f), n * high, 1e-5f);
}

TEST(MorphCompensation, GammaFormulaBalancesEnergyOverNFrames) {
  // N (H + L)^g = (L + H')^g + (N - 1) L^g, hand-checked value: L = 0.5, H = 0.1, N = 3, g = 2.2:
  // 3 * 0.6^2.2 = 0.97515, 2 * 0.5^2.2 = 0.43528, (0.53987)^(1/2.2) = 0.75562 -> H' = 0.2556.
  EXPECT_NEAR(compensated_high_frequency(0.1f, 0.5f, 3.0f, 2.2f), 0.2556f, 2e-4f);
  for (float g : {1.8f, 2.2f, 2.4f}) {
    const float l = 0.3f, h = 0.08f, n = 3.0f;
    const float hp = compensated_high_frequency(h, l, n, g);
    EXPECT_NEAR(std::pow(l + hp, g) + (n - 1.0f) * std::pow(l, g), n * std::pow(h + l, g), 1e-5f);
    EXPECT_GT(hp, n * h * 0.5f);  // a real amplification, not the identity
  }
}

TEST(MorphCompensation, DynamicRangeRulesConserveEnergy) {
  const float g = 2.2f;
  // Rule 1: original darker than its low-pass: kept in every frame.
  auto dark = compensate_value(0.2f, 0.35f, 2.0f, g);
  EXPECT_FLOAT_EQ(dark.top, 0.2f);
  EXPECT_FLOAT_EQ(dark.low, 0.2f);
  // Rule 2: the enhanced original would exceed 1: top = 1 and the low layer takes the excess.
  auto bright = compensate_value(0.95f, 0.6f, 2.0f, g);
  EXPECT_FLOAT_EQ(bright.top, 1.0f);
  EXPECT_GT(bright.low, 0.6f);
  EXPECT_NEAR(std::pow(bright.top, g) + 2.0f * std::pow(bright.low, g), 3.0f * std::pow(0.95f, g), 1e-3f);
  // Ordinary pixel: the paper's formula, L unchanged.
  auto mid = compensate_value(0.5f, 0.45f, 2.0f, g);
  EXPECT_NEAR(mid.top, 0.45f + compensated_high_frequency(0.05f, 0.45f, 3.0f, g), 1e-3f);
  EXPECT_FLOAT_EQ(mid.low, 0.45f);
  // Fractional blur sum (selective blur): energy still balances.
  auto part = compensate_value(0.6f, 0.5f, 0.7f, g);
  EXPECT_NEAR(std::pow(part.top, g) + 0.7f * std::pow(part.low, g), 1.7f * std::pow(0.6f, g), 1e-4f);
  // No blur: nothing changes.
  EXPECT_FLOAT_EQ(compensate_value(0.6f, 0.5f, 0.0f, g).top, 0.6f);
}

TEST(MorphCompensation, StaticImageMeanOverDisplayedFramesEqualsOriginalInLinearLight) {
  const int w = 64, h = 48, n = 3;
  // Texture with dark pixels (rule 1), bright pixels near 1 (rule 2) and mid-tones.
  Image color = test::make_color(w, h, [](float x, float y, int c) {
    const float v = test::texture(x, y, c);
    if (int(x) % 16 == 5) return 0.98f;   // bright lines: L + H' exceeds the range
    if (int(y) % 12 == 3) return 0.002f;  // dark lines: darker than their low-pass
    return v;
  });
  Image gb = test::make_gbuffer(w, h, [](int, int, float& mx, float& my, float& d) { mx = my = 0.0f; d = 5.0f; });
  MorphOptions o;
  o.factor = n;
  o.gamma = 2.2f;
  // Every in-between frame fully blurred, so the whole image is compensated.
  ASSERT_TRUE(apply_args(params(o), {"--min-blur", "1"}));
  Morpher m(o);
  std::vector<Image> out;
  ASSERT_TRUE(m.process(color, &gb, nullptr, out));
  ASSERT_EQ(out.size(), std::size_t(n));
  double max_err = 0.0, max_change0 = 0.0, max_change1 = 0.0;
  for (const char* ch : {"R", "G", "B"}) {
    const float* o0 = out[0].plane(ch);
    const float* src = color.plane(ch);
    for (std::size_t i = 0; i < color.pixel_count(); ++i) {
      double mean = 0.0;
      for (int k = 0; k < n; ++k) mean += out[std::size_t(k)].plane(ch)[i];
      mean /= n;
      max_err = std::max(max_err, std::abs(mean - double(src[i])));
      max_change0 = std::max(max_change0, std::abs(double(o0[i]) - src[i]));
      max_change1 = std::max(max_change1, std::abs(double(out[1].plane(ch)[i]) - src[i]));
      ASSERT_LE(o0[i], 1.0f + 1e-5f);  // the rendered frame stays inside the display range
      ASSERT_GE(o0[i], 0.0f);
    }
  }
  EXPECT_LT(max_err, 2e-4);
  // Not the identity: the rendered frame is sharpened and the in-between frames are blurred.
  EXPECT_GT(max_change0, 0.05);
  EXPECT_GT(max_change1, 0.05);
}

TEST(EyeTracking, CubicSmoothStepBetween70And90DegreesPerSecond) {
  EXPECT_FLOAT_EQ(eye_tracking_factor(0.0f), 1.0f);
  EXPECT_FLOAT_EQ(eye_tracking_factor(70.0f), 1.0f);
  EXPECT_FLOAT_EQ(eye_tracking_factor(80.0f), 0.5f);
  EXPECT_FLOAT_EQ(eye_tracking_factor(90.0f), 0.0f);
  EXPECT_FLOAT_EQ(eye_tracking_factor(200.0f), 0.0f);
  EXPECT_NEAR(eye_tracking_factor(75.0f), 1.0f - (0.25f * 0.25f * (3.0f - 0.5f)), 1e-6f);
  // Flat ends (f'(70) = f'(90) = 0).
  EXPECT_NEAR(eye_tracking_factor(70.01f), 1.0f, 1e-5f);
  EXPECT_NEAR(eye_tracking_factor(89.99f), 0.0f, 1e-5f);
  // 1 m wide screen seen from 0.5 m spans 90 degrees: 900 pixels -> 10 pixels per degree.
  EXPECT_NEAR(pixels_per_degree(1.0f, 0.5f, 900), 10.0f, 1e-4f);
}

TEST(EyeTracking, DampsVertexMotionOfUntrackableSpeeds) {
  const int w = 64, h = 64;
  // 100 px per frame at 40 fps and 40 pixels per degree: 100 deg/s, beyond tracking -> no motion.
  Image gb = test::make_gbuffer(w, h, [](int x, int, float& mx, float& my, float& d) {
    mx = x < 32 ? -100.0f : -20.0f;  // right half: 20 deg/s, tracked
    my = 0.0f;
    d = 1.0f;
  });
  GridOptions go;
  go.pixels_per_degree = 40.0f;
  go.fps = 40.0;
  go.snap = false;
  GridBuilder b;
  SnappedGrid g;
  b.build(gb.plane("motion.X"), gb.plane("motion.Y"), gb.plane("depth.Z"), w, h, go, g);
  const int j = 4;
  EXPECT_FLOAT_EQ(g.mx[std::size_t(j * g.nx + 2)], 0.0f);     // x = 16: 100 deg/s
  EXPECT_FLOAT_EQ(g.mx[std::size_t(j * g.nx + 6)], -20.0f);   // x = 48: 20 deg/s
}

}  // namespace
}  // namespace temporal::morph
