// herzog's options (seed 000 sections 3.3-3.5), shared by its C++ implementation (herzog.cpp) and its GLSL one
// (herzog_gpu.cpp), which must read the same fields. Internal (not installed), like method.h.
#pragma once

#include "method.h"

#include "temporal/core/method.h"
#include "temporal/core/params.h"
#include "temporal/upsample/history.h"

#include <limits>
#include <string>

namespace temporal::upsample {

// The coefficients of q in the adaptive image kernel's 2^f = 1 + f q(f) on [0, 1), highest degree first: the
// degree-4 q whose largest relative error over [0, 1) is smallest with the constant term of 2^f held at 1 (Remez
// exchange; 1.6e-7 measured over the float inputs, herzog_impl.inc's kernel_exp2). The C++ kernels and the GLSL one
// (herzog_gpu.cpp) evaluate it with the same multiply-adds.
inline constexpr float kKernelExp2[5] = {0.0018671300724412605f, 0.009017030315885468f, 0.05579991310967993f,
                                         0.24016445015286791f, 0.6931513118048799f};

// herzog's parameters (seed 000 sections 3.3-3.5; the choices are in docs/upsample-st.md).
struct HerzogOptions {
  float kernel_gamma = kMaxKernelGamma;      // gamma of k; 4 so that w_f = 1 reaches the cap
  float max_kernel_gamma = kMaxKernelGamma;  // cap of gamma * w_f (section 3.5: 4)
  float min_kernel_gamma = 0.0f;             // floor of the fall-off (the paper: 0)
  std::string fallback = "spatial";          // k at gamma w_f = 0: spatial's hat (default) or flat (eq. 3 alone)
  float a = 1.0f;                            // eq. 8 sensitivity
  bool favor_spatial = false;                // a = 0.7, the paper's elephant scene
  int gradient_scale = 2;                    // the gradient at full / scale (section 4: "e.g. at 2x2 pixels")
  float gradient_mip_level = 2.5f;           // spatial low-pass: trilinear mip level, in full-resolution levels
  float max_history_weight = 0.0f;           // bound of h_w; 0 = 2 k^2
  bool lagged_wf = false;                    // eq. 7 with the previous frame's w_f: one fused pass
  // Ablations (issue 16): which part of the gradient-driven adaptation carries the gain.
  float fixed_wf = -1.0f;                    // >= 0: w_f is this constant everywhere (no eq. 8)
  std::string gradient_filter = "temporal";  // none: |g_t| instead of |(0.4, 0.3, 0.2, 0.1) . (g_t..g_t-3)|

  float sensitivity() const { return favor_spatial ? kFavorSpatialA : a; }
  ParamList params() {
    return {
        Param::real("--kernel-gamma", "gamma of the image kernel k; the fall-off used is min(gamma w_f, cap)",
                    &kernel_gamma, 0.0, 1000.0),
        Param::real("--max-kernel-gamma", "cap of gamma w_f (seed 000 section 3.5: 4)", &max_kernel_gamma, 0.0, 1000.0),
        Param::real("--min-kernel-gamma",
                    "floor of the fall-off, max(G0, min(gamma w_f, cap)) (the paper: 0)", &min_kernel_gamma, 0.0,
                    1000.0),
        Param::choice("--fallback",
                      "k at gamma w_f = 0 (seed 000 sections 3.3, 3.5: \"falls back to spatial upsampling\"): "
                      "spatial = the spatial baseline's hat times eq. 3; flat = eq. 3 alone (the literal reading: "
                      "a box)",
                      &fallback, {"spatial", "flat"}),
        Param::real("--a", "sensitivity a of eq. 8 (w_f = a (1 - |grad|)^2)", &a, 0.0, 1.0),
        Param::flag_on("--favor-spatial", "a = 0.7 (the paper's elephant scene)", &favor_spatial),
        Param::integer("--gradient-scale",
                       "the temporal gradient is kept at full/S resolution, S a power of 2 (seed 000 section 4)",
                       &gradient_scale, 1, 8),
        Param::real("--gradient-mip-level",
                    "spatial low-pass of the gradient: trilinear mip level, counted at full resolution",
                    &gradient_mip_level, 0.0, 8.0),
        Param::real("--max-history-weight", "bound of the history weight h_w; 0 = 2 k^2", &max_history_weight, 0.0,
                    1e6),
        Param::flag_on("--lagged-wf",
                       "eq. 7 with the previous frame's w_f (motion-compensated): one pass instead of three, w_f "
                       "reacts one frame later",
                       &lagged_wf),
        Param::real("--fixed-wf",
                    "ablation: w_f is this constant in [0, 1] everywhere instead of eq. 8 (the kernel and eq. 7 "
                    "stop adapting to the gradient; a miss still restarts the history); -1 = off (eq. 8)",
                    &fixed_wf, -1.0, 1.0),
        Param::choice("--gradient-filter",
                      "temporal filter of the gradient (section 3.5.1): temporal = |(0.4, 0.3, 0.2, 0.1) . (g_t, "
                      "g_t-1, g_t-2, g_t-3)|; none = |g_t| (ablation)",
                      &gradient_filter, {"temporal", "none"}),
    };
  }
  Status check() const {
    if (fixed_wf < 0.0f && fixed_wf != -1.0f)
      return Error::usage("--fixed-wf " + std::to_string(fixed_wf) + " must be in [0, 1], or -1 for eq. 8");
    if (gradient_scale & (gradient_scale - 1))
      return Error::usage("--gradient-scale " + std::to_string(gradient_scale) + " is not a power of 2 (1, 2, 4, 8)");
    return Status::ok();
  }
};


// The run's herzog options (the defaults when the run has none).
const HerzogOptions& herzog_options(const Options& o);

}  // namespace temporal::upsample
