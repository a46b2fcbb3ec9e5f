// `taau`: an engine-class temporal upscaler, the modern baseline of issue 15, written from the public descriptions
// of AMD FidelityFX Super Resolution 2 (FSR 2: the GDC 2022 talk "FidelityFX Super Resolution 2.0" and its MIT
// shader source, ffx_fsr2_upsample.h / ffx_fsr2_accumulate.h / ffx_fsr2_lock.h, versions 2.0-2.2) and of Unreal
// Engine 4's TAAU (Karis 2014, "High Quality Temporal Supersampling": YCoCg neighbourhood clamp of the history).
// Not a port: one CPU pass per frame over full-resolution rows, with the choices below (docs/upsample-st.md, "taau",
// lists each with its source). taau_impl.inc runs each step below as a plain loop over a tile of the row (planar
// buffers, every branch computed and selected), so that the compiler vectorises it (issue 27).
//
// Per full-resolution pixel p (this frame's jittered low-resolution samples sit at full-resolution pixel centres,
// docs/conventions.md, "Jitter"):
//  1. History (FSR 2 "ReprojectHistoryColor"): the previous output, its accumulation weight and its lock at
//     p + motion through the shared reprojection module (temporal/core/reproject.h): off-screen rule, bilinear taps,
//     per-tap depth (and id) disocclusion test, FSR 2's depth clip. A miss makes p a "new sample". The colour is
//     re-read with the module's Catmull-Rom fetch (UE4) where all four bilinear taps were kept.
//  2. Reconstruction of this frame's samples (FSR 2 ComputeUpsampledColorAndWeight): the 3x3 low-resolution
//     samples around the nearest one, each weighted by Lanczos-2 (FSR 2's polynomial approximation
//     Lanczos2ApproxSq) of its offset from p in low-resolution pixels times the kernel bias (min(1.99, k) with
//     history, 1 for a new sample: a wider, smoother kernel where there is nothing to accumulate); the sum of
//     weights / 12 (fUpsampleLanczosWeightScale) is the new sample's accumulation weight; the result is clamped to
//     the samples' range (FSR 2 "Deringing", the negative lobes must not ring).
//  3. Rectification (FSR 2 RectifyHistory; Karis 2014): in YCoCg, a box of the 3x3 samples, mean +- s sigma with
//     weights exp(c |offset|^2) intersected with their min/max; a history outside it is moved towards it (fully
//     when far outside) and its accumulation weight falls towards 0.1 alike, unless a lock protects it.
//  4. Accumulation (FSR 2.0 Accumulate): per-pixel weight a := min(a, max) + w_new, output = history + (new -
//     history) w_new / a; max = 1 (fMaxAccumulationLanczosWeight), 3/12 while the pixel moves (accumulationMaxOnMotion).
//  5. Locks (FSR 2 ffx_fsr2_lock.h, ComputeThinFeatureConfidence): a low-resolution sample that is a luminance
//     ridge no 2x2 quad of similar neighbours explains (a thin feature: wire, edge highlight) locks its pixel; a lock
//     re-detected while alive gets lifetime 2, and a lifetime above 1 keeps the history from being clamped. The
//     lifetime decreases with the accumulated weight (one jitter cycle of average weight takes 1) and the lock dies on
//     a disocclusion or when the luminance under it changes by more than 10 %.
// Colour channels are rectified in YCoCg in threes (R, G, B of each payload layer; any channels left over one by one).
#include "taau.h"
#include "gpu_methods.h"

#include "temporal/core/color.h"
#include "temporal/core/isa.h"
#include "temporal/core/parallel.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cwchar>
#include <limits>

namespace temporal::upsample {

const TaauOptions& taau_options(const Options& o) { return method_options<TaauOptions>(o.per_method, "taau"); }

namespace {

// FSR 2's Lanczos2ApproxSq (from FSR 1's EASU): Lanczos-2 without sin or sqrt, of the squared distance x2:
// (25/16 (2/5 x2 - 1)^2 - (25/16 - 1)) (1/4 x2 - 1)^2 for x2 < 4, else 0. 1 at 0, 0 at 1, a negative lobe on (1, 2).
inline float lanczos2_approx_sq(float x2) {
  x2 = std::min(x2, 4.0f);
  const float a = 0.4f * x2 - 1.0f, b = 0.25f * x2 - 1.0f;
  return (25.0f / 16.0f * a * a - (25.0f / 16.0f - 1.0f)) * b * b;
}

// The frame code's copies, one per instruction set (temporal/core/isa.h); a state runs the copy of the level
// active when it was made. v3 and v4 may contract multiply-adds into FMAs (v2 has none): v2's output can differ
// from theirs in the last bits.
#define TEMPORAL_ISA_FILE "taau_impl.inc"
#include "temporal/core/isa_copies.inc"

std::unique_ptr<MethodState> make_state(const Options& o, const Geometry& g) {
  TEMPORAL_ISA_CALL(copy, return std::make_unique<copy::TaauState>(o, g))
}

// depth + N (the frame context's sample validity), payload in and out; motion, id; the previous depth and id read
// and written; the history read; weight, lock lifetime and lock luminance read and written.
std::size_t streamed_bytes(const Options&, int W, int H, int k, int C) {
  const std::size_t full = std::size_t(W) * H * 4, low = full / (std::size_t(k) * k);
  return 4 * full + C * low + C * full + 2 * full + full + 2 * (2 * full) + C * full + 3 * 2 * full;
}

}  // namespace

const MethodEntry& taau_method() {
  static const MethodEntry entry{
      .info = {.name = "taau",
               .summary = "engine-class temporal upscaler after FSR 2 / UE4 TAAU: Lanczos-2 reconstruction of the "
                          "jittered samples, depth disocclusion, YCoCg history clamp, per-pixel accumulation "
                          "weight, thin-feature locks",
               .has_state = true},
      .make_options = OptionsOf<TaauOptions>::make,
      .layers = history_method_layers,
      .implementations = {{kCpuDevice,
                           make_state},
                          // taau_gpu.cpp: the same steps as GLSL kernels, the same state planes.
                          {kGpuDevice, gpu_implementation<make_taau_state_gpu>}},
      .streamed_bytes = streamed_bytes};
  return entry;
}

}  // namespace temporal::upsample
