// The spatial and temporal coherence framework of seed 002 (Drobot, GPU Pro 2 chapter 7): closed-form
// per-pixel pieces, used by the `drobot` method of upsample-st and unit-tested one by one.
//
// Listing 7.1  bilateral upsampling: weight = normal^contrast * 1 / (1e-4 + |dz|) * bilinear table entry.
// Listing 7.2  reprojection cache with depth-based cache-miss detection (bilinear depth) and a running
//              convergence factor; exponential history h(t) = h(t-1) w + r (1 - w).
// Listing 7.3  separable depth-aware bilateral filter, taps at +-1.5 and +-3.5 texels (hardware linear
//              filtering), centre weight 0.4026 and tap weights 0.2442, 0.0545.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

namespace temporal::upsample {

// Listing 7.3 constants (a Gaussian sampled with linear filtering; they sum to 1).
inline constexpr float kDrobotCenterWeight = 0.402619947f;
inline constexpr float kDrobotTapOffsets[4] = {-3.5f, -1.5f, 1.5f, 3.5f};
inline constexpr float kDrobotTapWeights[4] = {0.054488685f, 0.244201342f, 0.244201342f, 0.054488685f};
inline constexpr float kDrobotE = 1.0f;  // `E` of Listing 7.3
// Listing 7.1: depthWeights = 1 / (0.0001 + |depthDiff|).
inline constexpr float kDrobotDepthBias = 1e-4f;

// Listing 7.1 normal weight: pow(max(0, n_low . n_high), contrast). (The listing writes
// `dot(normalsLow[i] + normalHi)`, a typo for the dot product of the two.)
inline float drobot_normal_weight(float dot, float contrast) { return std::pow(std::max(0.0f, dot), contrast); }

// Listing 7.1 depth weight: 1 / (1e-4 + |dz|), dz in units of the depth range (far - near): the listing's
// constant assumes depth in [0, 1].
inline float drobot_depth_weight(float dz_normalised) { return 1.0f / (kDrobotDepthBias + std::abs(dz_normalised)); }

// The precomputed bilinear weight table of Listing 7.1 / Figure 7.2 for factor k: entry [texelNo * 4 + i]
// is the bilinear weight of coarse sample i (0: top-left, 1: top-right, 2: bottom-left, 3: bottom-right)
// for the full-resolution pixel at offset (texelNo mod k, texelNo div k) from the top-left sample.
inline std::vector<float> drobot_bilinear_table(int k) {
  std::vector<float> t(std::size_t(k) * k * 4);
  for (int dy = 0; dy < k; ++dy)
    for (int dx = 0; dx < k; ++dx) {
      const float fx = float(dx) / float(k), fy = float(dy) / float(k);
      float* e = &t[std::size_t(dy * k + dx) * 4];
      e[0] = (1 - fx) * (1 - fy);
      e[1] = fx * (1 - fy);
      e[2] = (1 - fx) * fy;
      e[3] = fx * fy;
    }
  return t;
}

// Listing 7.2 cache test, as a history confidence in [0, 1]. The listing computes
// saturate((|lastDepth - cachedDepth| - threshold) * convergenceTime) and sets it to 0 outside the screen,
// then uses it as the weight of the cached value: read literally a larger depth mismatch would trust the
// cache more. We use the intended reading: confidence = 1 - saturate((|dz| - threshold) * convergenceTime),
// 0 outside the screen. dz is relative to the current depth.
inline float drobot_cache_confidence(float dz_relative, float threshold, float convergence_time, bool inside) {
  if (!inside) return 0.0f;
  const float miss = std::clamp((std::abs(dz_relative) - threshold) * convergence_time, 0.0f, 1.0f);
  return 1.0f - miss;
}

// Exponential history of section 7.2: h(t) = h(t-1) w + r (1 - w).
inline float exponential_history(float h_prev, float r, float w) { return h_prev * w + r * (1.0f - w); }

// Running convergence (frames accumulated) and the convergence weight w of the exponential history: the
// cached frame count n_prev is scaled by the cache confidence, capped at max_frames - 1, and
// w = n / (n + 1) (a running mean over at most max_frames frames, the length of the sample pattern).
inline float drobot_convergence_weight(float n_prev, float confidence, float max_frames, float* n_new) {
  const float n = std::min(n_prev * confidence, max_frames - 1.0f);
  if (n_new) *n_new = n + 1.0f;
  return n / (n + 1.0f);
}

// One tap pair of Listing 7.3: weight 1 / (E + amp |z_c - z_t|) times the Gaussian tap weight.
inline float drobot_filter_tap_weight(float z_center, float z_tap, float amp, float tap_weight) {
  return tap_weight / (kDrobotE + amp * std::abs(z_center - z_tap));
}

}  // namespace temporal::upsample
