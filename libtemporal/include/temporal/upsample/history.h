// The exponential history buffer and the temporal weighting of seed 000 (Herzog et al. 2010), sections
// 3.4 and 3.5: closed-form per-pixel functions, used by the `herzog` method and unit-tested one by one.
//
// Quantities (all dimensionless):
//   h~, w~  spatial upsampling result of this frame and its sum of weights (eq. 6);
//   h_r, h_w  history payload and history weight, fetched at the motion-compensated position i(t-1);
//   w_f     temporal confidence in [0, a] (eq. 8);
//   relative gradient  (h(t) - h(t-1)) / max(|h(t)|, |h(t-1)|), in [-2, 2] in general, [-1, 1] for
//           non-negative payloads (section 3.5.1).
#pragma once

#include <algorithm>
#include <cmath>

namespace temporal::upsample {

// Temporal filter of the finite differences (section 3.5.1): weights of the current and the three previous
// relative gradients.
inline constexpr float kGradientWeights[4] = {0.4f, 0.3f, 0.2f, 0.1f};
// Largest relative gradient magnitude used (disoccluded pixels get it, section 3.5.1 and Figure 6).
inline constexpr float kMaxGradient = 1.0f;
// Largest fall-off of the image-space kernel: gamma * w_f at most 4 (section 3.5).
inline constexpr float kMaxKernelGamma = 4.0f;

// Sensitivity a of eq. 8 for the paper's elephant scene (section 5: "we used a = 0.7"), `--favor-spatial`.
inline constexpr float kFavorSpatialA = 0.7f;

// Eq. 7 with the history's weight w_hist = w_f h_w already multiplied out (the per-pixel form herzog runs: the
// product also feeds the weight update): h = (h~ w~ + w_hist h_r) / (w~ + w_hist). With no weight at all
// (w~ = 0 and no history) the spatial estimate h~ is returned.
inline float history_blend_weighted(float h_tilde, float w_tilde, float w_hist, float h_r) {
  const float den = w_tilde + w_hist;
  return den > 0.0f ? (h_tilde * w_tilde + w_hist * h_r) / den : h_tilde;
}

// Eq. 7: h = (h~ w~ + w_f h_w h_r) / (w~ + w_f h_w).
inline float history_blend(float h_tilde, float w_tilde, float w_f, float h_w, float h_r) {
  return history_blend_weighted(h_tilde, w_tilde, w_f * h_w, h_r);
}

// History weight update after eq. 7, h_w := w~ + w_hist (w_hist = w_f h_w), bounded by `max_weight`. Without the
// bound h_w grows without limit in static regions (w_f = 1), so a new sample would eventually weigh nothing and
// float precision would be lost; bounded, eq. 7 becomes an exponential moving average whose newest
// frame has at least the weight w~ / (w~ + max_weight).
inline float bounded_history_weight(float w_tilde, float w_hist, float max_weight) {
  return std::min(w_tilde + w_hist, max_weight);
}
inline float history_weight_update(float w_tilde, float w_f, float h_w, float max_weight) {
  return bounded_history_weight(w_tilde, w_f * h_w, max_weight);
}

// Relative temporal gradient of section 3.5.1: (cur - prev) / max(|cur|, |prev|); 0 when both are 0.
inline float relative_gradient(float cur, float prev) {
  const float m = std::max(std::abs(cur), std::abs(prev));
  return m > 0.0f ? (cur - prev) / m : 0.0f;
}

// Temporally filtered gradient magnitude |grad . (0.4, 0.3, 0.2, 0.1)| of the current (g0) and three
// previous (g1..g3) relative gradients.
inline float filtered_gradient(float g0, float g1, float g2, float g3) {
  return std::abs(kGradientWeights[0] * g0 + kGradientWeights[1] * g1 + kGradientWeights[2] * g2 +
                  kGradientWeights[3] * g3);
}

// Eq. 8: w_f = a (1 - |gradient|)^2, the gradient magnitude clamped to [0, 1] first (a relative gradient
// can reach 2 for payloads that change sign; (1 - 2)^2 would wrongly give full confidence).
inline float temporal_weight(float gradient, float a = 1.0f) {
  const float g = std::min(std::abs(gradient), 1.0f);
  return a * (1.0f - g) * (1.0f - g);
}

// Fall-off of the image-space kernel k (section 3.5): gamma * w_f, at most 4.
inline float kernel_gamma(float gamma, float w_f, float cap = kMaxKernelGamma) { return std::min(gamma * w_f, cap); }

}  // namespace temporal::upsample
