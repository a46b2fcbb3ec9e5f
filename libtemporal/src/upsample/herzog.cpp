// `herzog`: spatio-temporal upsampling, seed 000 sections 3.3-3.5.
//
// Per frame, three passes (run row by row in one sweep, see HerzogFrame::build_schedule):
//  A (full resolution): spatial estimate h~ and its weight w~ (eq. 6) with the
//    image kernel k = hat g(|x(i) - x(j)|, r, min(gamma w_f, 4)) (section 3.3/3.5, the fallback below); motion-compensated fetch
//    of the history h_r, h_w (temporal/core/reproject.h); relative temporal gradient of the payload's luminance
//    (section 3.5.1), set to its maximum where the history is disoccluded (Figure 6), averaged into the
//    intermediate-resolution gradient buffer (section 4: "compute it at an intermediate resolution").
//  B (intermediate resolution): temporal filter |(0.4, 0.3, 0.2, 0.1) . (g_t .. g_t-3)| with the three
//    previous gradients motion-compensated; spatial low-pass by a box pyramid sampled trilinearly at
//    level 2.5 (the paper's mip level, counted at full resolution); w_f = a (1 - |grad|)^2 (eq. 8).
//  C (full resolution): eq. 7 blend and the bounded history update h_w := min(w~ + w_f h_w, max).
// Several loops pin their floating-point roundings (functions compiled with fp-contract=off and explicit
// std::fma): GCC fuses a * b + c depending on the surrounding code, and these loops must give the same bits
// wherever they are inlined (upsample_golden checks every output against a stored run).
//
// The kernel's fall-off needs w_f before h~ exists, and w_f needs h~ (the paper approximates h(i, t) by h~);
// we break the cycle by shaping the kernel with the previous frame's w_f at the motion-compensated position
// (0 where there is no history), and use this frame's w_f in eq. 7.
//
// The fallback (`--fallback`): section 3.3 says that for gamma = 0 "the results approach spatial upsampling" and
// section 3.5 that the method "falls back to spatial filtering", but eq. 3 at gamma = 0 is a constant kernel (a box
// over the four taps), not the spatial baseline's hat (section 3.1, [Yang et al. 2008]); the box is 0.65-1.9 dB
// below the hat on the built-in scenes (issue 15). By default k is the hat times eq. 3,
// k(i, j) = hat(x(i) - x(j)) g(||x(i) - x(j)||, r, gamma w_f): at gamma w_f = 0 it is exactly the spatial baseline's
// kernel, and as gamma w_f grows it still tends to the dirac of temporally-amortised upsampling (both factors are 1
// at distance 0). `--fallback flat` keeps eq. 3 alone, the literal reading.
#include "method.h"

#include "temporal/upsample/history.h"
#include "temporal/core/isa.h"
#include "temporal/core/parallel.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

namespace temporal::upsample {
namespace {

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
                    std::numeric_limits<double>::infinity()),
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

const HerzogOptions& herzog_options(const Options& o) { return method_options<HerzogOptions>(o.per_method, "herzog"); }

// The frame code's copies, one per instruction set (temporal/core/isa.h); a state runs the copy of the level
// active when it was made. v3 and v4 may contract multiply-adds into FMAs (v2 has none) outside the row kernels
// compiled with fp-contract=off, so v2's output can differ from theirs in the last bits.
#if TEMPORAL_ISA_DISPATCH
namespace v2 {
#include "herzog_impl.inc"
}  // namespace v2
TEMPORAL_ISA_V3_BEGIN
namespace v3 {
#include "herzog_impl.inc"
}  // namespace v3
TEMPORAL_ISA_END
TEMPORAL_ISA_V4_BEGIN
namespace v4 {
#include "herzog_impl.inc"
}  // namespace v4
TEMPORAL_ISA_END
#else
namespace native {
#include "herzog_impl.inc"
}  // namespace native
#endif

std::unique_ptr<MethodState> make_state(const Options& o, const Geometry& g) {
#if TEMPORAL_ISA_DISPATCH
  switch (isa::active()) {
    case isa::Level::V4: return std::make_unique<v4::HerzogState>(o, g);
    case isa::Level::V3: return std::make_unique<v3::HerzogState>(o, g);
    default: return std::make_unique<v2::HerzogState>(o, g);
  }
#else
  return std::make_unique<native::HerzogState>(o, g);
#endif
}

// --- Registry entry --------------------------------------------------------------------------------------------

// depth + N, payload in and out; motion, id; the previous depth and id read and written; the history read; h_w
// read and written.
std::size_t streamed_bytes(const Options&, int W, int H, int k, int C) {
  const std::size_t full = std::size_t(W) * H * 4, low = full / (std::size_t(k) * k);
  return 4 * full + C * low + C * full + 2 * full + full + 2 * (2 * full) + C * full + 2 * full;
}

// The gradient grid's size depends on --gradient-scale.
std::string state_layout(const Options& o) { return "gradient-scale " + std::to_string(herzog_options(o).gradient_scale); }

}  // namespace

const MethodEntry& herzog_method() {
  static const MethodEntry entry{
      .info = {.name = "herzog",
               .summary = "spatio-temporal upsampling (seed 000 sections 3.3-3.5): exponential history (eq. 6-7), "
                          "adaptive image kernel, w_f from the filtered relative gradient (eq. 8)",
               .has_state = true,
               .variants = {{"herzog-lagged", "herzog", {"--lagged-wf"},
                             "eq. 7 with the previous frame's w_f: one fused pass"},
                            {"herzog-favor-spatial", "herzog", {"--favor-spatial"},
                             "a = 0.7 (the paper's elephant scene)"}}},
      .make_options = OptionsOf<HerzogOptions>::make,
      .layers = history_method_layers,
      .implementations = {{kCpuDevice,
                           make_state}},
      .streamed_bytes = streamed_bytes,
      .state_layout = state_layout};
  return entry;
}

}  // namespace temporal::upsample
