// Sequence comparison, the engine of the `compare` tool: streams a reference and any number of test
// sequences frame by frame (only the current frame and the previous frame's luminance are in memory), computes
// PSNR, SSIM and flicker (temporal/metrics/metrics.h, temporal/metrics/flicker.h) per frame and per test, optionally inside and
// outside a mask layer, writes error maps, and turns the results into CSV, JSON, charts and threshold checks.
// docs/compare.md defines every number.
#pragma once

#include "temporal/core/error.h"
#include "temporal/core/sequence.h"

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace temporal {

struct ComparisonSetup {
  std::string reference;               // reference sequence pattern (REF.####.exr)
  std::vector<std::string> tests;      // test sequence patterns
  std::vector<std::string> names;      // one per test; empty: derived from the file names
  std::string layer = "rgb";           // compared layer of the tests (temporal/metrics/metrics.h compared_channels)
  std::string reference_layer;         // compared layer of the reference; empty: same as `layer`
  std::string gbuffer;                 // G-buffer pattern with `motion`; empty: flicker without compensation
  std::string mask;                    // mask layer or channel; empty: none. Looked up in each test, then the
                                       // G-buffer, then the reference (first frame's header)
  std::optional<FrameRange> frames;    // empty: every reference frame on disk
  double peak = 1.0;                   // PSNR / SSIM peak L (units of the pixel values)
  bool peak_from_data = false;         // idiff's rule per frame: max(1, largest finite value of both images)
  std::string error_maps;              // folder for <name>.####.exr error maps; empty: none
  std::string tool;                    // `temporal:tool` of the error maps
  std::string parameters;              // `temporal:parameters` of the error maps
};

// Metrics of one test frame. NaN means "no value" (no pixel compared); PSNR is +infinity for identical images.
struct FrameMetrics {
  int frame = 0;
  double peak = 1.0;       // the peak used for this frame
  double mse_rgb = 0.0;    // mean over valid pixels and compared channels of (test - reference)^2
  double psnr_rgb = 0.0;   // dB, over every compared channel
  double psnr_y = 0.0;     // dB, on luminance
  double ssim = 0.0;       // MSSIM on luminance
  std::optional<double> flicker;  // RMS of d_t (temporal/metrics/flicker.h); absent at the first frame and camera cuts
  std::size_t flicker_pixels = 0;
  std::size_t nonfinite_test = 0;       // pixels with a NaN/Inf in the test (excluded)
  std::size_t nonfinite_reference = 0;  // pixels with a NaN/Inf in the reference (excluded)
  std::size_t valid_pixels = 0;         // pixels that entered PSNR
  // Inside / outside the mask (only with a mask). mask_fraction: share of valid pixels inside.
  bool has_mask = false;
  double mask_fraction = 0.0;
  double psnr_rgb_inside = 0.0, psnr_rgb_outside = 0.0;
  double psnr_y_inside = 0.0, psnr_y_outside = 0.0;
  double ssim_inside = 0.0, ssim_outside = 0.0;
  std::optional<double> flicker_inside, flicker_outside;
  // From the test file's header: `temporal:computeMs` and `temporal:ms:<pass>` (milliseconds).
  std::optional<double> compute_ms;
  std::map<std::string, double> timings_ms;
  double metrics_ms = 0.0;  // time compare spent on this frame's metrics (I/O excluded)
};

struct SequenceReport {
  std::string name;
  std::string pattern;
  std::string mask_source;  // "test", "gbuffer", "reference" or empty
  std::vector<FrameMetrics> frames;
};

struct ComparisonReport {
  std::string reference;
  std::string gbuffer;
  std::string layer;
  std::string reference_layer;
  std::string mask;
  std::vector<std::string> channels;            // compared channels of the tests
  std::vector<std::string> reference_channels;  // compared channels of the reference
  int width = 0, height = 0;
  std::vector<int> frames;
  bool motion_compensated = false;
  double peak = 1.0;
  bool peak_from_data = false;
  std::vector<SequenceReport> sequences;
};

// Observers of a running comparison (the library never prints; the tool decides what to show).
struct ComparisonHooks {
  std::function<void(int frame, int done, int total)> frame_done;  // after each frame (done of total)
  std::function<void(const std::string& file, const std::string& text)> warning;  // e.g. NaN pixels found
  std::function<void(const std::string& text)> log;                           // details for --verbose
};

// Runs the comparison. Errors: Usage (bad setup), Input (missing/corrupt files, missing layers, size or
// channel-count mismatch, empty sequence), Output (error maps not writable).
Expected<ComparisonReport> compare_sequences(const ComparisonSetup& setup, const ComparisonHooks& hooks = {});

// The name `compare` gives a test sequence without --names: the file name without folder, frame number and
// extension (`out/taa.####.exr` -> `taa`).
std::string sequence_name(const std::string& pattern);

// --- Summaries -------------------------------------------------------------------------------------------

enum class Metric { PsnrRgb, PsnrY, Ssim, Flicker };
// "psnr_rgb", "psnr_y", "ssim", "flicker"
const char* metric_name(Metric metric);
// True when larger values are better (PSNR, SSIM).
bool metric_higher_is_better(Metric metric);
// The per-frame value, NaN when the frame has none (flicker of the first frame).
double metric_value(const FrameMetrics& frame, Metric metric);

struct MetricSummary {
  std::size_t count = 0;  // frames with a value
  double mean = 0.0;      // mean of the per-frame values (+inf if any PSNR frame is +inf)
  double min = 0.0, max = 0.0;
  int min_frame = 0, max_frame = 0;
  double worst() const { return higher_is_better ? min : max; }  // min for PSNR/SSIM, max for flicker
  bool higher_is_better = true;
};
MetricSummary summarize(const SequenceReport& sequence, Metric metric);

// Mean of `temporal:computeMs` over frames that have it (else the mean sum of the `temporal:ms:*` timings).
std::optional<double> mean_compute_ms(const SequenceReport& sequence);

// --- Thresholds (compare --fail-*) -----------------------------------------------------------------------

struct Thresholds {
  std::optional<double> psnr;     // fail when PSNR (RGB) < psnr dB
  std::optional<double> ssim;     // fail when SSIM < ssim
  std::optional<double> flicker;  // fail when flicker > flicker
  bool worst_frame = false;       // judge the worst frame instead of the sequence mean
};
struct ThresholdFailure {
  std::string sequence;
  Metric metric = Metric::PsnrRgb;
  double value = 0.0;
  double limit = 0.0;
  std::string message() const;  // "taa: mean psnr_rgb 28.1 dB < 30 dB"
};
std::vector<ThresholdFailure> check_thresholds(const ComparisonReport& report, const Thresholds& thresholds);

// --- Outputs (written atomically: temporary file, then rename) --------------------------------------------

// One row per frame and test sequence; infinite PSNR is written `inf`, missing values are empty fields.
Status write_comparison_csv(const ComparisonReport& report, const std::string& path);
// Summary per sequence (mean, min, max of each metric, timings), inputs and threshold results. Infinite
// values are the string "inf", missing values null.
Status write_comparison_json(const ComparisonReport& report, const Thresholds& thresholds,
                             const std::vector<ThresholdFailure>& failures, const std::string& tool,
                             const std::string& parameters, const std::string& path);

}  // namespace temporal
