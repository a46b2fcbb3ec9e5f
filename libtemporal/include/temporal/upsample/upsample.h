// Upsampling of a jittered low-resolution shading payload to full resolution with a full-resolution
// G-buffer: the methods of seed 000 (Herzog et al. 2010) and seed 002 (Drobot 2011), used by `upsample-st`.
//
// The methods are units listed in one table (temporal/upsample/methods.h; libtemporal/src/upsample/registry.cpp):
//   spatial   joint-bilateral upsampling, seed 000 eq. 1-3 (hat image kernel)            [joint_bilateral.h]
//   temporal  temporally-amortised upsampling, seed 000 eq. 4: pixels shaded this frame are kept, the
//             others are fetched from the previous output at p + motion; disocclusions have no history and
//             are filled spatially and counted ("hole pixels")                           [temporal/core/reproject.h]
//   herzog    spatio-temporal upsampling, seed 000 sections 3.3-3.5: exponential history (eq. 6-7),
//             image kernel with fall-off gamma * w_f, w_f from the filtered relative gradient (eq. 8)  [history.h]
//   drobot    seed 002: reprojection cache at low resolution + exponential history with convergence,
//             convergence-steered separable bilateral filter, Listing 7.1 bilateral upsampling; or its
//             refresh-buffer reconstruction (Figure 7.12, `--mode refresh`)                 [drobot.h]
//   taau      engine-class temporal upscaler after FSR 2 / UE4 TAAU: Lanczos-2 reconstruction, YCoCg history
//             rectification, per-pixel accumulation weight, thin-feature locks                [src/upsample/taau.cpp]
//
// Inputs per frame (docs/conventions.md): the G-buffer at full resolution (`depth.Z`, `N.X/Y/Z`,
// `motion.X/Y`, `id`; metadata clipNear/clipFar) and the payload at 1/k resolution per axis with
// `temporal:jitterFactor` k and `temporal:jitter` / `temporal:jitterIndex`. With the antialiasing variant
// (seed 000 section 4, `aa_factor` m > 1) the G-buffer is m x m the output resolution and the result is
// box-downsampled by m.
//
// State: each method keeps its histories in its own state object, allocated when the frame size is first
// seen and reused for every frame; process() allocates nothing per pixel. Non-finite payload values are counted
// and never enter a history. save_state() / load_state() carry everything the next frame needs (--state-out /
// --state-in), so that a resumed run is bit-identical to an uninterrupted one.
#pragma once

#include "temporal/core/error.h"
#include "temporal/core/image.h"
#include "temporal/core/method.h"
#include "temporal/core/params.h"
#include "temporal/core/reproject.h"
#include "temporal/upsample/joint_bilateral.h"

#include <cstddef>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace temporal::upsample {

// Every registered method's own parameters (temporal/core/method.h), with their defaults.
MethodOptionSet default_method_options();

// Options of the upsampling stage. The defaults are here (shared parameters) and in each method's options struct
// (MethodOptions); the command line binds to them through params().
struct Options {
  std::string method = "herzog";  // a name of the registry (temporal/upsample/methods.h)
  std::string layer = "rgb";      // payload layers: `rgb` (bare R,G,B) or layer names, comma-separated
  std::string device = "cpu";     // the implementation's device: "cpu" or "gpu" (temporal/core/method.h)

  // --- seed 000, section 3.1 (spatial weights, every method) ---
  float sigma_normal = kSigmaNormal;                 // sigma_n of eq. 2
  float sigma_depth_fraction = kSigmaDepthFraction;  // sigma_d = fraction * (clipFar - clipNear)
  float sigma_depth = 0.0f;                          // > 0: absolute sigma_d (world units), overrides the fraction

  // --- the history fetch (temporal/core/reproject.h: the disocclusion test every history method uses) ---
  float depth_tolerance = reproject::kDepthTolerance;  // relative depth difference of a disoccluded tap
  bool no_ids = false;                                 // depth only: do not compare material ids (Figure 3)
  // Seed 000 section 3.2 compares the warped depth: with a G-buffer layer prevDepth.Z (the depth each pixel's
  // surface point had in the previous frame) the test compares it, at warped_depth_tolerance, instead of the
  // current depth at depth_tolerance. no_depth_velocity ignores the layer (ablation).
  float warped_depth_tolerance = reproject::kWarpedDepthTolerance;
  bool no_depth_velocity = false;

  // --- seed 000 section 4 ---
  int aa_factor = 1;  // m: G-buffer is m x m the output; the result is box-downsampled
  // Split the shader (section 4: "most high-frequency components (such as textures ...) are not expensive and
  // could be efficiently computed for every pixel"): colour channels (R, G, B, or X.R, X.G, X.B) are divided
  // by the G-buffer albedo at their sample pixel before upsampling, the method (and its history) works on the
  // untextured lighting, and the result is multiplied by the full-resolution albedo. Off by default: the
  // paper's own results "refrained from such decompositions".
  bool demodulate = false;

  bool debug_layers = false;  // add debug.* layers to the result

  MethodOptionSet per_method = default_method_options();  // each method's own parameters

  // The disocclusion test of the history fetch (with prevDepth.Z, reproject::expect_depth sets the warped
  // tolerance).
  reproject::SurfaceTest surface_test() const { return {depth_tolerance, !no_ids}; }
};

// Every parameter of the stage, pointing at the fields of `options`: the shared ones, then each method's (help
// prefixed with the method's name). Valid while `options` lives and is not moved.
ParamList params(Options& options);

// Options for `method` with parameters set by command-line style arguments (apply_args), e.g.
// make_options("drobot", {"--mode", "refresh"}). Usage error for an unknown method or parameter.
Expected<Options> make_options(const std::string& method, const std::vector<std::string>& args = {});

// The selected method's own parameters as the arguments that set them, every one with its value (defaults
// included; flags only when on), e.g. "--kernel-gamma 4 --max-kernel-gamma 4 ... --a 0.7 --gradient-scale 2":
// the `temporal:methodParameters` header of every output, so a result says which a, cap, mode, ... made it.
// make_options(method, split(text)) gives the same options (values to 6 significant digits). Empty for a method
// without parameters.
std::string method_parameters(const Options& options);

// Usage error unless every value is valid: the method exists, every parameter is inside its range, and each
// method's own checks pass.
Status check(const Options& options);

// What happened in one frame.
struct FrameStats {
  std::size_t non_finite_input = 0;  // low-resolution payload values that were NaN or Inf
  std::size_t hole_pixels = 0;       // full-res pixels neither shaded this frame nor with valid history
  std::size_t history_pixels = 0;    // full-res pixels whose history was valid
  bool history_reset = false;        // history was discarded (first frame, cut, reset, size change)
  double compute_ms = 0.0;           // time spent in process(), I/O excluded (on the GPU: the kernels' time)
  std::string compute_clock;         // how compute_ms was measured (gpu::compute_clock_name)
  double wall_ms = 0.0;              // process()'s wall-clock time (on the GPU with the uploads and downloads)
};

// Where the frame came from, only for error messages.
struct FrameNames {
  std::string gbuffer;
  std::string input;
};

// Layers of the G-buffer the method reads (for read_exr's selection): its own, plus `albedo` with demodulation.
std::vector<std::string> gbuffer_layers(const Options& options);

// Payload channels for a `--layer` value: "rgb" = R,G,B; "NAME" = NAME.* of `low`; a comma-separated list
// takes several. An Input error when a layer is missing.
Expected<std::vector<std::string>> select_channels(const Image& low, const std::string& layers,
                                                   const std::string& file);

class Upsampler {
 public:
  // `options` must pass check(); an unknown method makes every process() fail with a usage error.
  explicit Upsampler(Options options);
  ~Upsampler();
  Upsampler(const Upsampler&) = delete;
  Upsampler& operator=(const Upsampler&) = delete;

  const Options& options() const;
  // The GPU context of a --device gpu run (made with the first frame's state); null on the CPU.
  const gpu::Context* gpu_context() const;

  // Upsamples one frame. `channels` names the payload channels of `low` to rebuild. `cut` discards the
  // history first (also done on the first frame, a size change, or `temporal:cameraCut` in either header).
  // The result holds the same channel names at output resolution (+ debug.* layers when enabled); it is
  // owned by the Upsampler and valid until the next call. Errors: Input (missing layers, sizes that do
  // not match full = k * low, missing jitter metadata, jitter off the regular pattern, a loaded state of another
  // size), Usage (bad options).
  Expected<Image*> process(const Image& gbuffer, const Image& low, std::span<const std::string> channels, bool cut,
                           FrameStats* stats = nullptr, const FrameNames& names = {});

  // Discards every history.
  void reset();

  // Whether the method keeps anything between frames (spatial does not).
  bool has_state() const;
  // Everything the next frame needs (histories, weights, gradients, previous depth and ids), as planes of an
  // image at the G-buffer's size (smaller planes in its top-left corner), with the method, sizes and channels in
  // its header (docs/upsample-st.md, "State files"). Usage error before the first frame or without state.
  Expected<Image> save_state() const;
  // Resumes from a save_state() image: the next process() continues as if the frames before had just been
  // processed. Checked now: the method and its options that shape the state; at the next process(): the frame
  // size, k and channels (an Input error there names --state-in), the planes the method reads and their values
  // (an Input error for a missing plane or a non-finite value where --state-out writes none: histories, drobot's
  // cache). `source` names the file in those later errors (the frame's input otherwise).
  Status load_state(const Image& state, std::string source = {});

  // Bytes per frame a method must read and write at this size (streaming bound of the benchmark).
  static std::size_t streamed_bytes(const Options& options, int full_width, int full_height, int k, int channels);

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace temporal::upsample
