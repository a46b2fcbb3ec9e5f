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
#include "herzog.h"
#include "gpu_methods.h"

#include "temporal/upsample/history.h"
#include "temporal/core/isa.h"
#include "temporal/core/parallel.h"

#include <immintrin.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numeric>
#include <type_traits>

namespace temporal::upsample {

const HerzogOptions& herzog_options(const Options& o) { return method_options<HerzogOptions>(o.per_method, "herzog"); }

namespace {

// The frame code's copies, one per instruction set (temporal/core/isa.h); a state runs the copy of the level
// active when it was made. v3 and v4 may contract multiply-adds into FMAs (v2 has none) outside the row kernels
// compiled with fp-contract=off, so v2's output can differ from theirs in the last bits.
#define TEMPORAL_ISA_FILE "herzog_impl.inc"
#include "temporal/core/isa_copies.inc"

std::unique_ptr<MethodState> make_state(const Options& o, const Geometry& g) {
  TEMPORAL_ISA_CALL(copy, return std::make_unique<copy::HerzogState>(o, g))
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
                           make_state},
                          // herzog_gpu.cpp: the same passes as GLSL kernels, the same state planes.
                          {kGpuDevice, gpu_implementation<make_herzog_state_gpu>}},
      .streamed_bytes = streamed_bytes,
      .state_layout = state_layout};
  return entry;
}

}  // namespace temporal::upsample
