// Each closed-form equation of seeds 000 and 002 against values computed by hand.
#include "temporal/upsample/drobot.h"
#include "temporal/upsample/history.h"
#include "temporal/upsample/joint_bilateral.h"

#include <gtest/gtest.h>

#include <cmath>

namespace up = temporal::upsample;

TEST(UpsampleEquations, Eq3KernelG) {
  // g(x, sigma, gamma) = max(eps, 1 - x/sigma)^gamma
  EXPECT_FLOAT_EQ(up::kernel_g(0.5f, 2.0f, 3.0f), 0.421875f);  // 0.75^3
  EXPECT_FLOAT_EQ(up::kernel_g(1.0f, 4.0f, 2.0f), 0.5625f);    // 0.75^2
  EXPECT_FLOAT_EQ(up::kernel_g(3.0f, 1.0f, 1.0f), up::kKernelEpsilon);  // clamped, never zero
  EXPECT_FLOAT_EQ(up::kernel_g(0.7f, 1.0f, 0.0f), 1.0f);       // gamma = 0: constant (spatial)
}

TEST(UpsampleEquations, TriWeight) {
  // g(x^2, sigma^2, 3): x = 0.1, sigma = 0.2 -> (1 - 0.25)^3 = 0.421875
  EXPECT_FLOAT_EQ(up::tri_weight(0.1f, 0.2f), 0.421875f);
  EXPECT_FLOAT_EQ(up::tri_weight(0.0f, 0.2f), 1.0f);
  EXPECT_FLOAT_EQ(up::tri_weight(0.3f, 0.2f), up::kKernelEpsilon * up::kKernelEpsilon * up::kKernelEpsilon);
}

TEST(UpsampleEquations, Eq2NormalAndDepthTerms) {
  // n . n = 0.9 -> x = 0.1 -> tri-weight with sigma_n = 0.2: 0.421875
  EXPECT_NEAR(up::normal_weight(0.9f), 0.421875f, 1e-6f);
  EXPECT_FLOAT_EQ(up::normal_weight(1.0f), 1.0f);
  EXPECT_FLOAT_EQ(up::normal_weight(1.2f), 1.0f);  // max(0, 1 - dot): never above 1
  // sigma_d = 3% of (100 - 0.1) = 2.997; |dz| = 1.4985 -> (1 - 0.25)^3
  const float sd = 0.03f * (100.0f - 0.1f);
  EXPECT_NEAR(up::depth_weight(10.0f, 10.0f + 0.5f * sd, sd), 0.421875f, 1e-6f);
  EXPECT_NEAR(up::depth_weight(10.0f, 50.0f, sd), 1e-9f, 1e-12f);
}

TEST(UpsampleEquations, Eq2GeometricWeightIsTheProductOfItsTerms) {
  // The per-pixel form every kernel runs: n . n = 0.9 (0.421875, above) and |dz| = sigma_d / 2 (0.421875):
  // 0.421875^2 = 0.177978515625.
  const float sd = 0.03f * (100.0f - 0.1f);
  const float inv_sn2 = 1.0f / (0.2f * 0.2f), inv_sd2 = 1.0f / (sd * sd);
  EXPECT_NEAR(up::geometric_weight(0.9f, 0.5f * sd, inv_sn2, inv_sd2), 0.177978515625f, 1e-6f);
  // Both terms clamped at epsilon: eps^3 * eps^3.
  EXPECT_NEAR(up::geometric_weight(-1.0f, 10.0f * sd, inv_sn2, inv_sd2), 1e-18f, 1e-21f);
  // Equal to normal_weight * depth_weight over a grid of inputs. The two forms round 1 - x^2 / sigma^2 differently
  // (a product with 1 / sigma^2 against a quotient); near the edge of the tent the cancellation makes that a few
  // 1e-6 relative (measured: at most 2.9e-6 on this grid), hence 1e-5.
  for (float dot = -0.2f; dot <= 1.0f; dot += 0.05f)
    for (float dz = -1.2f * sd; dz <= 1.2f * sd; dz += 0.1f * sd) {
      const float product = up::normal_weight(dot) * up::depth_weight(10.0f, 10.0f - dz, sd);
      EXPECT_NEAR(up::geometric_weight(dot, dz, inv_sn2, inv_sd2), product, 1e-5f * product + 1e-30f)
          << "dot " << dot << " dz " << dz;
    }
}

TEST(UpsampleEquations, ImageKernelsSection33) {
  const float r = 4.0f * std::sqrt(2.0f);  // low-res pixel diagonal for k = 4
  // distance 1, gamma 4: (1 - 1/5.656854)^4 = 0.823223^4 = 0.459273
  EXPECT_NEAR(up::image_kernel(1.0f, r, 4.0f), 0.459273f, 1e-5f);
  EXPECT_FLOAT_EQ(up::image_kernel(0.0f, r, 4.0f), 1.0f);
  EXPECT_FLOAT_EQ(up::hat_kernel(1.0f, 3.0f, 4), 0.75f * 0.25f);
  EXPECT_FLOAT_EQ(up::hat_kernel(-4.0f, 0.0f, 4), 0.0f);
}

TEST(UpsampleEquations, JitterGridMatchesConventions) {
  up::JitterGrid g{4, 1, 2};
  EXPECT_EQ(g.tap0_x(0), -1);  // X = 0 lies left of the first sample (at X = 1)
  EXPECT_EQ(g.tap0_x(1), 0);
  EXPECT_EQ(g.tap0_x(4), 0);
  EXPECT_EQ(g.tap0_x(5), 1);
  EXPECT_EQ(g.tap0_y(1), -1);
  EXPECT_EQ(g.tap0_y(2), 0);
  EXPECT_TRUE(g.computed(5, 6));   // (4*1+1, 4*1+2)
  EXPECT_FALSE(g.computed(6, 6));
}

TEST(UpsampleEquations, Eq7HistoryBlend) {
  // (h~ w~ + w_f h_w h_r) / (w~ + w_f h_w) = (0.2*1 + 0.5*4*0.8) / (1 + 2) = 1.8 / 3 = 0.6
  EXPECT_FLOAT_EQ(up::history_blend(0.2f, 1.0f, 0.5f, 4.0f, 0.8f), 0.6f);
  EXPECT_FLOAT_EQ(up::history_blend(0.2f, 1.0f, 0.0f, 4.0f, 0.8f), 0.2f);  // w_f = 0: spatial only
  EXPECT_FLOAT_EQ(up::history_blend(0.3f, 0.0f, 0.0f, 0.0f, 0.8f), 0.3f);  // no weight at all
  // The per-pixel form with w_hist = w_f h_w = 2 multiplied out: the same 0.6.
  EXPECT_FLOAT_EQ(up::history_blend_weighted(0.2f, 1.0f, 2.0f, 0.8f), 0.6f);
  EXPECT_FLOAT_EQ(up::history_blend_weighted(0.3f, 0.0f, 0.0f, 0.8f), 0.3f);
  EXPECT_FLOAT_EQ(up::bounded_history_weight(1.0f, 2.0f, 32.0f), 3.0f);
  EXPECT_FLOAT_EQ(up::bounded_history_weight(1.0f, 40.0f, 32.0f), 32.0f);
  // h_w := w~ + w_f h_w, bounded
  EXPECT_FLOAT_EQ(up::history_weight_update(1.0f, 0.5f, 4.0f, 32.0f), 3.0f);
  EXPECT_FLOAT_EQ(up::history_weight_update(1.0f, 1.0f, 32.0f, 32.0f), 32.0f);
}

TEST(UpsampleEquations, RelativeGradientAndEq8) {
  EXPECT_FLOAT_EQ(up::relative_gradient(0.6f, 0.4f), 0.2f / 0.6f);
  EXPECT_FLOAT_EQ(up::relative_gradient(0.4f, 0.6f), -0.2f / 0.6f);
  EXPECT_FLOAT_EQ(up::relative_gradient(0.0f, 0.0f), 0.0f);
  // |0.4*0.5 + 0.3*(-0.5) + 0.2*0.25 + 0.1*1| = |0.2 - 0.15 + 0.05 + 0.1| = 0.2
  EXPECT_FLOAT_EQ(up::filtered_gradient(0.5f, -0.5f, 0.25f, 1.0f), 0.2f);
  // A periodic +-g flicker cancels in the filter: |0.4 - 0.3 + 0.2 - 0.1| g = 0.2 g
  EXPECT_FLOAT_EQ(up::filtered_gradient(1.0f, -1.0f, 1.0f, -1.0f), 0.2f);
  // eq. 8: a (1 - |g|)^2
  EXPECT_FLOAT_EQ(up::temporal_weight(0.2f), 0.64f);
  EXPECT_FLOAT_EQ(up::temporal_weight(-0.5f, 0.7f), 0.175f);
  EXPECT_FLOAT_EQ(up::temporal_weight(1.5f), 0.0f);  // clamped at |g| = 1
  EXPECT_FLOAT_EQ(up::kernel_gamma(4.0f, 0.64f), 2.56f);
  EXPECT_FLOAT_EQ(up::kernel_gamma(10.0f, 1.0f), 4.0f);  // gamma * w_f at most 4
}

TEST(DrobotEquations, Listing71Weights) {
  EXPECT_NEAR(up::drobot_normal_weight(0.9f, 32.0f), std::pow(0.9f, 32.0f), 1e-7f);  // 0.034337
  EXPECT_FLOAT_EQ(up::drobot_normal_weight(-0.5f, 32.0f), 0.0f);
  EXPECT_FLOAT_EQ(up::drobot_depth_weight(0.0f), 10000.0f);
  EXPECT_NEAR(up::drobot_depth_weight(0.0099f), 100.0f, 1e-3f);
  const auto table = up::drobot_bilinear_table(2);  // Figure 7.2: 2x2 tile
  // texel 3 = offset (1, 1): fx = fy = 0.5 -> 0.25 each
  for (int i = 0; i < 4; ++i) EXPECT_FLOAT_EQ(table[3 * 4 + i], 0.25f);
  // texel 1 = offset (1, 0): (0.5, 0.5, 0, 0)
  EXPECT_FLOAT_EQ(table[1 * 4 + 0], 0.5f);
  EXPECT_FLOAT_EQ(table[1 * 4 + 1], 0.5f);
  EXPECT_FLOAT_EQ(table[1 * 4 + 2], 0.0f);
  EXPECT_FLOAT_EQ(table[0 * 4 + 0], 1.0f);
}

TEST(DrobotEquations, Listing72CacheAndHistory) {
  // 1 - saturate((|dz| - thr) * T)
  EXPECT_FLOAT_EQ(up::drobot_cache_confidence(0.01f, 0.02f, 50.0f, true), 1.0f);
  EXPECT_FLOAT_EQ(up::drobot_cache_confidence(0.03f, 0.02f, 50.0f, true), 0.5f);
  EXPECT_FLOAT_EQ(up::drobot_cache_confidence(0.2f, 0.02f, 50.0f, true), 0.0f);
  EXPECT_FLOAT_EQ(up::drobot_cache_confidence(0.0f, 0.02f, 50.0f, false), 0.0f);  // outside the buffer
  // h(t) = h(t-1) w + r (1 - w)
  EXPECT_FLOAT_EQ(up::exponential_history(1.0f, 0.0f, 0.75f), 0.75f);
  float n = 0;
  EXPECT_FLOAT_EQ(up::drobot_convergence_weight(3.0f, 1.0f, 16.0f, &n), 0.75f);  // running mean of 4
  EXPECT_FLOAT_EQ(n, 4.0f);
  EXPECT_FLOAT_EQ(up::drobot_convergence_weight(40.0f, 1.0f, 16.0f, &n), 15.0f / 16.0f);  // bounded
  EXPECT_FLOAT_EQ(n, 16.0f);
  EXPECT_FLOAT_EQ(up::drobot_convergence_weight(8.0f, 0.0f, 16.0f, &n), 0.0f);  // cache miss
  EXPECT_FLOAT_EQ(n, 1.0f);
}

TEST(DrobotEquations, Listing73Constants) {
  float sum = up::kDrobotCenterWeight;
  for (float w : up::kDrobotTapWeights) sum += w;
  EXPECT_NEAR(sum, 1.0f, 1e-6f);
  // 1 / (E + amp |dz|) * w: amp 200, dz 0.005 -> w / 2
  EXPECT_NEAR(up::drobot_filter_tap_weight(1.0f, 1.005f, 200.0f, 0.244201342f), 0.244201342f / 2.0f, 1e-5f);
}
