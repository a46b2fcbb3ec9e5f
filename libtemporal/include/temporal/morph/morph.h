// Temporal upsampling of rendered frames for high-refresh-rate displays: seed 004 (Didyk et al. 2010,
// "Perceptually-motivated real-time temporal upsampling of 3D content for high-refresh-rate displays") and
// the baselines it is measured against.
//
// One rendered frame n (scene-linear colour R,G,B, assumed display-referred: 1.0 is the display's peak) and its
// G-buffer (motion.X/Y, depth.Z) become `factor` displayed frames, slot k = 0 .. factor-1 at time
// (n + k/factor) / fps. Slot 0 is the rendered frame itself (with `didyk`: high-frequency compensated),
// slots k >= 1 are extrapolated from frame n and its motion, with no added latency (except `blend`).
//
// Methods are units listed in one registry (temporal/morph/methods.h: name, what each reads, its parameters and
// latency, its implementations); docs/morph-120hz.md has the details and every choice the paper leaves open:
//  - didyk:  snapped grid morph + depth test + selective blur + high-frequency compensation (sections 5-6).
//  - repeat: every slot shows frame n (a 40 Hz stream on a 120 Hz hold-type display).
//  - blend:  slot k = (1 - k/N) frame n + (k/N) frame n+1 in linear light; needs frame n+1, so it adds one
//            rendered frame of latency (the last frame, without a successor, is repeated).
//  - warp:   per-pixel forward warp of frame n with a depth test, holes left black (no hole filling).
// The sequence tool around them (frame numbering, fps, NaN policy, --perceive) is temporal/morph/morph_stage.h.
#pragma once

#include "temporal/core/error.h"
#include "temporal/core/method.h"
#include "temporal/morph/grid_warp.h"
#include "temporal/core/image.h"
#include "temporal/core/viewing.h"  // pixels_per_degree (eye-tracking limit)
#include "temporal/morph/blur_pyramid.h"

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace temporal::morph {

class MorphMethod;  // temporal/morph/methods.h
struct MethodEntry;

// Every registered method's own parameters (temporal/morph/methods.h), with their defaults.
MethodOptionSet default_method_options();

// The options of a run: the method, what every method shares, and each method's own parameters (didyk's grid,
// blur and compensation: src/morph/didyk.cpp, DidykOptions).
struct MorphOptions {
  std::string method = "didyk";  // a name of the registry (temporal/morph/methods.h)
  std::string device = "cpu";    // the implementation's device: "cpu" or "gpu" (temporal/core/method.h)
  int factor = 3;                // displayed frames per rendered frame, >= 2 (40 Hz -> 120 Hz: 3)
  float gamma = 2.2f;            // display gamma g: displayed light = value^g, value in [0, 1]
  // The eye-tracking limit (seed 004 section 6): pixels per degree of the viewing geometry (<= 0: no limit) and the
  // rendered sequence's frame rate. The sequence stage sets both from ViewingOptions and the input's rate
  // (morph_stage.h).
  float pixels_per_degree = 0.0f;
  double fps = 40.0;
  bool debug_layers = false;  // add debug.grid, debug.distortion, debug.blur, debug.H, debug.Hprime
  MethodOptionSet per_method = default_method_options();
};

// Usage error unless the options are valid for any input: a known method, factor >= 2, gamma > 0, and every
// method's own parameters (didyk: a grid cell that is a power of two in [2, 32], blur level in [0, 8]).
// Morpher::process checks them too.
Status check(const MorphOptions& options);

// The debug layers every output carries with MorphOptions::debug_layers (zero where a method has nothing to show).
inline constexpr const char* kMorphDebugLayers[5] = {"debug.grid", "debug.distortion", "debug.blur", "debug.H",
                                                     "debug.Hprime"};

// Milliseconds spent per stage for one rendered frame (all its in-between frames), seed 004 Table 1.
struct MorphTimings {
  double flow_ms = 0.0;   // flow gradient, max-pyramid, snapping, vertex motion and damping
  double morph_ms = 0.0;  // vertex extrapolation, distortion, rasterisation of every in-between frame
  double blur_ms = 0.0;   // blur pyramid, tri-cubic reconstruction, compensation, blur-strength map
  double total_ms() const { return flow_ms + morph_ms + blur_ms; }
};

// Seed 004 section 5.1: the detail layer H' that makes the rendered frame plus N-1 frames showing only the
// low-pass L emit, integrated over the N frames, the energy of N frames of H + L on a display of gamma g:
//   N (H + L)^g = (L + H')^g + (N - 1) L^g  <=>  H' = (N (H + L)^g - (N - 1) L^g)^(1/g) - L.
// `frames` is N (real-valued: selective blur uses 1 + the sum of the in-between blur strengths). No range
// rules here; the result may need L + H' outside [0, 1].
float compensated_high_frequency(float high, float low, float frames, float gamma);

// One channel of a pixel after compensation with the dynamic-range rules of section 5.1. Values are
// display-encoded ([0, 1], light = value^g). `top` goes to the rendered frame; `low` is the low-frequency
// value the in-between frames show where they are blurred (strength b_k, blended in linear light).
struct CompensatedValue {
  float top = 0.0f;
  float low = 0.0f;
};
// original = H + L, low = L; blurred = sum over the in-between frames of their blur strength (N - 1 when all
// are fully blurred). Rules: an original darker than its low-pass is kept in every frame (top = low =
// original: no negative light is needed); when L + H' exceeds 1, the rendered frame shows 1 and the excess
// energy moves into the low-frequency layer of the in-between frames. Energy is conserved exactly:
//   top^g + blurred * low^g = (1 + blurred) * original^g   (for original in [0, 1]).
// Values outside [0, 1] are passed through (top = low = original).
CompensatedValue compensate_value(float original, float low, float blurred, float gamma);

// Upsamples rendered frames one at a time. Full-resolution scratch buffers are kept between calls (no
// per-pixel allocation; only grid-sized vectors are rebuilt per frame).
class Morpher {
 public:
  explicit Morpher(MorphOptions options);
  ~Morpher();
  Morpher(Morpher&&) noexcept;
  Morpher& operator=(Morpher&&) noexcept;
  const MorphOptions& options() const { return options_; }
  // The method's state (null before the first process()) and, with --device gpu, its context (else null).
  const MorphMethod* method() const { return method_.get(); }
  const gpu::Context* gpu_context() const { return gpu_.get(); }

  // color: R,G,B (float, scene-linear) of rendered frame n; gbuffer: the layers the method reads (its registry
  // entry: motion.X, motion.Y, depth.Z for didyk and warp; repeat and blend accept nullptr); next: colour of
  // frame n+1 (methods with lookahead, blend; nullptr repeats, others ignore it). Writes `factor` images (R,G,B
  // and, with debug_layers, the debug layers) into `out`, slot k = out[k]. Metadata is left to the caller.
  // Values must be finite (the sequence stage replaces NaN/Inf by 0). Errors: unknown method, missing
  // channels, mismatched sizes, factor < 2.
  Status process(const Image& color, const Image* gbuffer, const Image* next, std::vector<Image>& out,
                 MorphTimings* timings = nullptr);

 private:
  Status check(const Image& color, const Image* gbuffer, const Image* next) const;

  MorphOptions options_;
  const MethodEntry* entry_ = nullptr;  // registry entry of options_.method (set on first use)
  std::unique_ptr<MorphMethod> method_;    // its state (buffers kept between frames)
  std::shared_ptr<gpu::Context> gpu_;      // --device gpu: the method's context
};

}  // namespace temporal::morph
