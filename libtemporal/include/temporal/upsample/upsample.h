// Upsampling of a jittered low-resolution shading payload to full resolution with a full-resolution
// G-buffer: the methods of seed 000 (Herzog et al. 2010) and seed 002 (Drobot 2011), used by `upsample-st`.
//
//   spatial   joint-bilateral upsampling, seed 000 eq. 1-3 (hat image kernel)            [joint_bilateral.h]
//   temporal  temporally-amortised upsampling, seed 000 eq. 4: pixels shaded this frame are kept, the
//             others are fetched from the previous output at p + motion; disocclusions (depth + id,
//             Figure 3) have no history and are filled spatially and counted ("hole pixels")  [temporal/core/reproject.h]
//   herzog    spatio-temporal upsampling, seed 000 sections 3.3-3.5: exponential history (eq. 6-7),
//             image kernel with fall-off gamma * w_f, w_f from the filtered relative gradient (eq. 8)  [history.h]
//   drobot    seed 002: reprojection cache at low resolution + exponential history with convergence,
//             convergence-steered separable bilateral filter, Listing 7.1 bilateral upsampling; or its
//             refresh-buffer reconstruction (Figure 7.12, `DrobotMode::Refresh`)              [drobot.h]
//
// Inputs per frame (docs/conventions.md): the G-buffer at full resolution (`depth.Z`, `N.X/Y/Z`,
// `motion.X/Y`, `id`; metadata clipNear/clipFar) and the payload at 1/k resolution per axis with
// `temporal:jitterFactor` k and `temporal:jitter` / `temporal:jitterIndex`. With the antialiasing variant
// (seed 000 section 4, `aa_factor` m > 1) the G-buffer is m x m the output resolution and the result is
// box-downsampled by m.
//
// State: an Upsampler keeps its histories in buffers allocated once and reused for every frame; process()
// allocates nothing per pixel. Non-finite payload values are counted and never enter a history.
#pragma once

#include "temporal/core/error.h"
#include "temporal/core/image.h"

#include <cstddef>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace temporal::upsample {

enum class Method { Spatial, Temporal, Herzog, Drobot };
enum class DrobotMode { Cache, Refresh };

// Parses "spatial|temporal|herzog|drobot" and "cache|refresh".
Expected<Method> parse_method(const std::string& name);
Expected<DrobotMode> parse_drobot_mode(const std::string& name);
const char* method_name(Method m);

struct Options {
  Method method = Method::Herzog;

  // --- seed 000, section 3.1 (spatial weights) ---
  float sigma_normal = 0.2f;           // sigma_n of eq. 2
  float sigma_depth_fraction = 0.03f;  // sigma_d = fraction * (clipFar - clipNear)
  float sigma_depth = 0.0f;            // > 0: absolute sigma_d (world units), overrides the fraction

  // --- seed 000, sections 3.2-3.5 ---
  float depth_tolerance = 0.05f;  // relative depth difference above which a history tap is disoccluded
  bool use_ids = true;            // also compare material ids (Figure 3)
  float kernel_gamma = 4.0f;      // gamma of the image kernel k; the fall-off used is min(gamma * w_f, cap)
  float max_kernel_gamma = 4.0f;  // the cap of gamma * w_f (seed 000: 4)
  float min_kernel_gamma = 0.0f;  // floor of the fall-off (seed 000: 0, a flat kernel where w_f = 0)
  float a = 1.0f;                 // eq. 8 sensitivity (the paper's elephant scene used 0.7)
  int gradient_scale = 2;         // intermediate resolution of the gradient: full / scale (power of 2)
  float gradient_mip_level = 2.5f;  // spatial low-pass: trilinear mip level, in full-resolution levels
  float max_history_weight = 0.0f;  // bound of h_w; 0 = 2 * k * k (see docs/upsample-st.md)
  bool lagged_wf = false;           // eq. 7 with the previous frame's w_f (motion-compensated): one pass over
                                    // the image instead of three, w_f reacts one frame later

  // --- seed 002 ---
  DrobotMode drobot_mode = DrobotMode::Cache;
  float normal_power = 32.0f;       // contrastCoef of Listing 7.1
  bool drobot_normals = true;       // false: depth-only weights (the chapter's SSAO variant)
  float miss_threshold = 0.02f;     // IN_MissThreshold of Listing 7.2 (relative depth)
  float convergence_time = 50.0f;   // IN_ConvergenceTime of Listing 7.2
  float max_frames = 0.0f;          // frames in the exponential history; 0 = k * k (pattern length)
  float filter_amp = 200.0f;        // IN_BilateralFilterAmp of Listing 7.3 (per relative depth)
  bool cache_bilinear = true;       // cache values read with bilinear (true) or point (false) filtering; the
                                    // depth test always uses bilinear depth (Listing 7.2)

  // --- seed 000 section 4 ---
  int aa_factor = 1;  // m: G-buffer is m x m the output; the result is box-downsampled
  // Split the shader (section 4: "most high-frequency components (such as textures ...) are not expensive and
  // could be efficiently computed for every pixel"): colour channels (R, G, B, or X.R, X.G, X.B) are divided
  // by the G-buffer albedo at their sample pixel before upsampling, the method (and its history) works on the
  // untextured lighting, and the result is multiplied by the full-resolution albedo. Off by default: the
  // paper's own results "refrained from such decompositions".
  bool demodulate = false;

  bool debug_layers = false;  // add debug.* layers to the result
};

// What happened in one frame.
struct FrameStats {
  std::size_t non_finite_input = 0;  // low-resolution payload values that were NaN or Inf
  std::size_t hole_pixels = 0;       // full-res pixels neither shaded this frame nor with valid history
  std::size_t history_pixels = 0;    // full-res pixels whose history was valid
  bool history_reset = false;        // history was discarded (first frame, cut, reset, size change)
  double compute_ms = 0.0;           // time spent in process(), I/O excluded
};

// Where the frame came from, only for error messages.
struct FrameNames {
  std::string gbuffer;
  std::string input;
};

// Layers of the G-buffer each method reads (for read_exr's selection).
std::vector<std::string> gbuffer_layers(const Options& options);

// Counts non-finite values in the G-buffer layers the method reads.
std::size_t count_non_finite_gbuffer(const Image& gbuffer);

// Payload channels for a `--layer` value: "rgb" = R,G,B; "NAME" = NAME.* of `low`; a comma-separated list
// takes several. An Input error when a layer is missing.
Expected<std::vector<std::string>> select_channels(const Image& low, const std::string& layers,
                                                   const std::string& file);

class Upsampler {
 public:
  explicit Upsampler(Options options);
  ~Upsampler();
  Upsampler(const Upsampler&) = delete;
  Upsampler& operator=(const Upsampler&) = delete;

  const Options& options() const { return options_; }

  // Upsamples one frame. `channels` names the payload channels of `low` to rebuild. `cut` discards the
  // history first (also done on the first frame, a size change, or `temporal:cameraCut` in either header).
  // The result holds the same channel names at output resolution (+ debug.* layers when enabled); it is
  // owned by the Upsampler and valid until the next call. Errors: Input (missing layers, sizes that do
  // not match full = k * low, missing jitter metadata, jitter off the regular pattern).
  Expected<Image*> process(const Image& gbuffer, const Image& low, std::span<const std::string> channels, bool cut,
                           FrameStats* stats = nullptr, const FrameNames& names = {});

  // Discards every history.
  void reset();

  // Bytes per frame a method must read and write at this size (streaming bound of the benchmark).
  static std::size_t streamed_bytes(const Options& options, int full_width, int full_height, int k, int channels);

  struct State;

 private:
  Options options_;
  std::unique_ptr<State> state_;
  struct Demodulation;
  std::unique_ptr<Demodulation> demod_;
};

}  // namespace temporal::upsample
