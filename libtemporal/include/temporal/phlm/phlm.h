// Pixel History Linear Models (seed 003: Iglesias-Guitian, Moon, Koniaris, Smolikowski, Mitchell, Pacific
// Graphics 2016), sections 4-6 and Algorithm 1.
//
// Every pixel keeps a linear model f = beta^T x with predictor x = [1, z] (eq. 3), z the temporal feature of
// section 5.1 (an exponential accumulation of the low-frequency input colour). Each frame, per pixel:
// the model of the previous frame is fetched at p + motion (reset to the input when that is off-screen),
// its prediction is tested against the 3x3 neighbourhood colour box and, outside it, clipped along the ray
// towards the input and the model reset to the clipped colour (Algorithm 1 lines 13-19); the model is then
// updated by recursive least squares (eq. 5-7, temporal/phlm/rls.h) and predicts the output (eq. 8).
//
// Model size follows the data: C = 3 channels (RGB) give N = 4 predictors (beta 3x4, P 4x4); one channel
// (ambient occlusion `ssao.Y`, `shadow.Y`) gives N = 2 (beta 1x2, P 2x2). docs/filter-phlm.md lists how
// every loose term of the paper is read.
#pragma once

#include "temporal/core/error.h"
#include "temporal/phlm/frame_filter.h"
#include "temporal/core/image.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace temporal::phlm {

struct PhlmParams {
  float lambda = 0.998f;   // RLS forgetting factor (eq. 6-7, section 4)
  float p_init = 1000.0f;  // P = p_init * I at reset (section 6)
  float feature_a = 0.125f;  // phi(v, l) = a l^2 + b v l^3 (section 5.1)
  float feature_b = 0.25f;
  // trace(P) never exceeds trace_factor * N * p_init (temporal/phlm/rls.h, wind-up guard).
  float trace_factor = 4.0f;

  // Ablations and measured alternatives (docs/filter-phlm.md, "Ablations"); the defaults are the paper's method.
  // Feature off: the predictor is x = [1] (the slopes stay 0 and P's feature rows untouched), i.e. an
  // intercept-only RLS: a per-pixel exponentially weighted running mean (weight lambda^age) with the same resets.
  bool no_feature = false;
  // Box test off: Algorithm 1 lines 13-19 skipped; models are reset only off screen, at cuts and at frame 0.
  bool no_box_test = false;
  // Reading of the feature's alpha (section 5.1): "ue4" = weight of the new low-frequency sample (UE4's
  // BlendFinal, whose code the constants come from); "eq1" = the literal eq. 1 reading, alpha weighs the history:
  // z = alpha z_prev + (1 - alpha) low.
  std::string alpha_reading = "ue4";
  // Form of phi in the feature's weight alpha = phi(v, l) / (l + Delta(Y)) (section 5.1; docs/filter-phlm.md,
  // "The feature's weight"): "paper" = a l^2 + b v l^3 as printed, which keeps alpha ~ a l^2 / Delta, near 1e-4 on
  // noisy static pixels, so the feature barely moves between resets; "linear" = (a + b v) l, UE4's
  // HistoryFactor = DistToClamp * HistoryAmount (the code the paper says a, b come from), alpha ~ a l / Delta
  // (ablation, issue 24).
  std::string feature_phi = "paper";
  // Fetch of the previous models at p + motion: "bilinear" (section 6, hardware bilinear filtering of the model
  // textures), "nearest" (the record of the nearest pixel), "catmull-rom" (beta and the feature with the 4x4
  // Catmull-Rom taps of temporal/core/reproject.h, P's factors and the scale bilinearly: negative weights could
  // make P indefinite).
  std::string model_fetch = "bilinear";
};

// Floats of persistent state per pixel for C channels: beta (C * N), P as UD factors (N (N + 1) / 2),
// feature z (C) and the model's scale s (1), N = C + 1. RGB: 12 + 10 + 3 + 1 = 26 floats = 104 bytes;
// one channel: 2 + 3 + 1 + 1 = 7 floats = 28 bytes.
constexpr int phlm_state_floats(int channels) {
  const int n = channels + 1;
  return channels * n + n * (n + 1) / 2 + channels + 1;
}

class PhlmFilter final : public FrameFilter {
 public:
  explicit PhlmFilter(PhlmParams params = {});

  const PhlmParams& params() const { return params_; }

  // Filters one frame into `output` (same size, channels named like the input's; `debug.*` planes added when
  // in.debug: debug.featureR/G/B (or debug.feature), debug.alpha (feature blend weight), debug.reset (0 model
  // kept, 1 reset to input: off-screen/first frame/cut, 2 reset by the box test), debug.traceP).
  // The first frame after construction (or after a size or channel change) resets every model.
  // `output` is reused between calls: pass the same Image every frame to avoid allocations.
  Status process(const FilterInput& in, Image& output, FilterStats* stats = nullptr) override;

  // The models after the last frame, as an image of named planes (written by --state-out):
  //   beta.<c><k>  (c = channel suffix R, G, B or Y; k = 0..N-1: intercept then slopes)
  //   P.D<k>, P.U<ij>  (UD factors of P, temporal/phlm/rls.h), feature.<c>, scale.s
  // Empty before the first frame. `state_with_covariance` adds the packed symmetric P (Pmat.P<ij>, i <= j)
  // for inspection; set_state ignores it.
  Image state() const;
  Image state_with_covariance() const;
  // Resumes from a state written by state(): the next frame continues the same models (the output is bit
  // for bit what an uninterrupted run gives). Input error when planes are missing or not finite.
  Status set_state(const Image& state, int channels) override;
  // What --state-out writes: state_with_covariance().
  Image saved_state() const override { return state_with_covariance(); }
  std::string stats_text(const FilterStats& stats) const override;

  // Names of the state planes for C channels.
  static std::vector<std::string> state_channel_names(int channels);

 private:
  PhlmParams params_;
  // Models after the last frame and those being written for this frame (swapped), one interleaved record of
  // phlm_state_floats(C) floats per pixel (see phlm.cpp, Layout).
  PlaneVector<float> state_, next_;  // huge pages where the system gives them (temporal/core/image.h)
  int width_ = 0, height_ = 0;
  int channels_ = 0;
  bool have_state_ = false;
  std::vector<float> ycgco_[3];     // this frame's input in YCgCo (reused between frames)
  std::vector<std::uint8_t> valid_;  // 1 where every channel of the input pixel is finite
};

}  // namespace temporal::phlm
