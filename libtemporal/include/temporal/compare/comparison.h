// Sequence comparison, the engine of the `compare` tool: streams a reference and any number of test
// sequences frame by frame (only the current frame and the previous frame's luminance are in memory), measures
// every metric of the registry per frame and per test, optionally inside and outside a mask layer and per region
// of the frame (static / moving / disoccluded from the G-buffer, --regions motion), writes error maps, and turns
// the results into CSV, JSON, a summary table (with the pooled PSNR beside the mean of frames), charts and
// threshold checks. docs/compare.md defines every number.
//
// The metric set is open: a metric is one entry of the registry (metric_registry()) - its name, label, unit,
// the per-frame measure, the CSV columns it writes, whether higher is better, its threshold option
// `--fail-<option>`, its chart and its column of the summary table - and the CSV, JSON, thresholds, charts,
// pictures, table and `compare --list-metrics` iterate the registry. Adding a metric is one source file
// (src/compare/metric_<name>.cpp: the definition and its FrameMeasure, named in the stage's source list), one
// line in src/compare/registry.cpp, and its section in docs/compare.md.
#pragma once

#include "temporal/core/error.h"
#include "temporal/core/metadata.h"
#include "temporal/io/runner.h"
#include "temporal/core/sequence.h"
#include "temporal/metrics/flip.h"
#include "temporal/metrics/statistics.h"

#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace temporal {

class Image;

// FLIP in compare (temporal/metrics/flip.h): off, LDR-FLIP of the display-encoded frames (sRGB OETF of the
// values clamped to [0, 1]), or HDR-FLIP of the scene-linear values.
enum class FlipMode { Off, Ldr, Hdr };
// "off", "ldr", "hdr" (the values of `compare --flip`).
const char* flip_mode_name(FlipMode mode);

// --- Regions (compare --regions motion; docs/compare.md, "Regions") ----------------------------------------

// Every pixel of a compared frame is in exactly one region, decided from the G-buffer and the reference:
//   static:      zero motion (below kStaticMotion pixels in x and y), history found by the reprojection rules
//                (temporal/core/reproject.h), and the reference's luminance unchanged (within static_tolerance) from
//                each frame to the next over the last static_frames frames - all three at each of those frames;
//   disoccluded: no history by the reprojection rules - the fetch is off screen or fails the depth/id test of
//                temporal/core/reproject.h (the one the methods use), or there is no previous frame (the first
//                frame, a camera cut, a gap in --frames that no primed frame fills);
//   moving:      everything else (moving surfaces, and still surfaces whose shading changed, e.g. under a moving
//                shadow, or that were not still for static_frames frames yet).
enum : int { kRegionStatic = 0, kRegionMoving = 1, kRegionDisoccluded = 2, kRegionCount = 3, kAllRegions = -1 };
// "static", "moving", "disoccluded"; "all" for kAllRegions.
const char* region_name(int region);
// Motion below this (pixels, |x| and |y|) is zero: the float rounding of a static surface's reprojection.
inline constexpr double kStaticMotion = 1e-3;

struct RegionOptions {
  int static_frames = 10;          // --static-frames: frames the reference must have been unchanged
  double static_tolerance = 0.02;  // --static-tolerance: largest |Y_t - Y_{t-1}| of "unchanged" (pixel units)
};

// One frame's inputs of the classification (width * height planes).
struct RegionInputs {
  int width = 0, height = 0;
  const float* motion_x = nullptr;  // the G-buffer's motion (required)
  const float* motion_y = nullptr;
  const float* depth = nullptr;     // depth.Z; null with prev_depth null: only the off-screen rule
  const float* warped_depth = nullptr;       // prevDepth.Z when the G-buffer has it (reproject::expect_depth)
  const std::uint32_t* id = nullptr;         // material ids; null: no id test
  const float* previous_depth = nullptr;     // the previous frame's depth.Z
  const std::uint32_t* previous_id = nullptr;
  bool has_previous = false;                 // false: every pixel is disoccluded (no history at all)
  const float* reference_y = nullptr;        // the reference's luminance now and at the previous frame (NaN where
  const float* previous_reference_y = nullptr;  // not finite: never "unchanged")
};
// Classifies one frame: labels[i] = kRegionStatic, kRegionMoving or kRegionDisoccluded. `still` holds, per pixel,
// the number of consecutive frames up to this one with zero motion, a history hit and an unchanged reference; the
// caller keeps it between frames (zeros at the start) and this call updates it. A pixel is static when it
// reaches options.static_frames.
void classify_regions(const RegionInputs& in, const RegionOptions& options, std::span<std::uint16_t> still,
                      std::span<std::uint8_t> labels);

struct ComparisonSetup {
  std::string reference;               // reference sequence pattern (REF.####.exr)
  std::vector<std::string> tests;      // test sequence patterns
  std::vector<std::string> names;      // one per test; empty: derived from the file names
  std::string layer = "rgb";           // compared layer of the tests (temporal/metrics/metrics.h compared_channels)
  std::string reference_layer;         // compared layer of the reference; empty: same as `layer`
  std::string gbuffer;                 // G-buffer pattern with `motion`; empty: flicker without compensation
  std::string mask;                    // mask layer or channel; empty: none. Looked up in each test, then the
                                       // G-buffer, then the reference (first frame's header)
  bool regions = false;                // --regions motion: every metric also per region (needs `gbuffer` with
                                       // motion, depth.Z and id)
  RegionOptions region_options;
  std::optional<FrameRange> frames;    // empty: every reference frame on disk
  double peak = 1.0;                   // PSNR / SSIM peak L (units of the pixel values)
  bool peak_from_data = false;         // idiff's rule per frame: max(1, largest finite value of both images)
  FlipMode flip = FlipMode::Off;       // off by default: FLIP costs more than PSNR and SSIM together
  FlipOptions flip_options;            // viewing condition (pixels per degree) and HDR-FLIP settings
  std::string error_maps;              // folder for <name>.####.exr error maps; empty: none
  int warmup_frames = 0;               // the first N compared frames are summarised apart from the steady state
  // Also score each test frame t against the reference frame t + L shown at the same instant, L = the test's
  // `temporal:latencyFrames` (frames of its own sequence; absent: 0), as the `psnr_latency` metric
  // (docs/conventions.md, "Latency"). The reference is read past `frames` where the files exist.
  bool latency_aware = false;
  BootstrapOptions bootstrap;          // intervals of the JSON summary (temporal/metrics/statistics.h)
  // The metric judged against compute time: the speed chart's y axis and the JSON's Pareto flags (speed_points).
  std::string speed_metric = "psnr_rgb";
  std::string tool;                    // `temporal:tool` of the error maps
  std::string parameters;              // `temporal:parameters` of the error maps
};

// --- The metric registry -----------------------------------------------------------------------------------

inline constexpr double kNoValue = std::numeric_limits<double>::quiet_NaN();

// One metric on one test frame. values[k] belongs to MetricDefinition::columns[k]; the first is the primary
// value (the one summaries, thresholds, charts and the table use). NaN means "no value".
struct MetricSample {
  std::string metric;                // registry name
  std::vector<double> values;
  double inside = kNoValue;          // primary value over the pixels (or windows) inside the mask
  double outside = kNoValue;         // ... and outside it
  std::size_t count = 0;             // pixels or windows that entered the primary value
  // With --regions: the primary value over each region's pixels (kRegionStatic, ...); NaN where the metric has no
  // region value (docs/compare.md, "Regions": psnr_latency) or the region is empty.
  std::array<double, kRegionCount> regions{kNoValue, kNoValue, kNoValue};
};

// What a metric sees of one test frame. Planes are width * height floats, row-major.
struct FrameInputs {
  int frame = 0;
  int width = 0, height = 0;
  std::span<const float* const> test;        // compared channels of the test
  std::span<const float* const> reference;   // the reference's, same order
  std::span<const std::string> channels;     // names of the test's compared channels
  const float* test_y = nullptr;             // Rec.709 luminance of the compared channels (luminance_plane)
  const float* reference_y = nullptr;
  const std::uint8_t* valid = nullptr;       // 1 where every compared channel of both images is finite
  const float* mask = nullptr;               // inside: > 0.5; null without a mask
  // With --regions: each pixel's region (kRegionStatic, ...) and the same as one 0/1 plane per region (for the
  // kernels that take a mask); null without regions.
  const std::uint8_t* regions = nullptr;
  std::array<const float*, kRegionCount> region_masks{};
  double peak = 1.0;                         // PSNR / SSIM peak of this frame
  // The motion-compensated change of luminance since the previous frame (temporal_delta of the warped previous
  // luminance, temporal/metrics/flicker.h); null when the frame has no usable previous frame (first frame,
  // camera cut).
  const float* test_change = nullptr;
  const float* reference_change = nullptr;
  Image* maps = nullptr;                     // the frame's error-map image (add channels); null without maps
  // With ComparisonSetup::latency_aware: the test's latency L in frames (`temporal:latencyFrames`), the
  // reference's compared channels at frame + L (empty when that file does not exist) and the pixels where
  // they and the test are finite.
  int latency_frames = 0;
  std::span<const float* const> shown_reference;
  const std::uint8_t* shown_valid = nullptr;
};

// The per-frame work of one metric. One instance per comparison measures every test frame in turn, so it may
// keep scratch buffers between frames.
class FrameMeasure {
 public:
  virtual ~FrameMeasure() = default;
  // Fills out.values (one per column), out.inside / out.outside when in.mask is set, and out.count. An error's
  // file is filled in by the caller.
  virtual Status measure(const FrameInputs& in, MetricSample& out) = 0;
};

struct MetricColumn {
  std::string csv;   // CSV header of the per-frame value
  std::string json;  // key of its mean over frames in the metric's JSON summary; empty: CSV only. Unused for
                     // the first (primary) column, whose summary is the metric's JSON object itself
};

// The per-frame chart of the primary value (`--plot F.png` writes F<suffix>.png). In the title, "{layer}"
// becomes the compared layer and "{motion}" " (motion-compensated)" when a G-buffer was given.
struct MetricChart {
  std::string suffix;
  std::string title;
  std::string y_label;                 // with the unit: "PSNR (dB)"
  bool skip_without_values = false;    // no chart when no frame has a value (flicker of a single frame)
  // The range the metric's values can take (SSIM <= 1, FLIP in [0, 1], flicker >= 0): the chart's automatic
  // axis range never extends past them.
  std::optional<double> lowest;
  std::optional<double> highest;
};

struct MetricDefinition {
  std::string name;                    // "psnr_rgb": JSON key, threshold and failure name, table header
  std::string label;                   // "PSNR": what pictures and charts call it
  std::string unit;                    // "dB", or empty for a unitless metric
  bool higher_is_better = true;
  std::vector<MetricColumn> columns;   // CSV columns, primary first
  std::array<std::string, 2> mask_columns;  // CSV columns of the primary value inside / outside the mask
  // The four metrics compare always had keep their historical CSV places (pipelines parse them): primary
  // columns after `sequence`, other columns before `peak`, mask columns after `mask_fraction`. Every other
  // metric's columns (and then its mask columns) follow, in registry order.
  bool historical_csv = false;
  std::string threshold_option;        // "psnr" gives `--fail-psnr`; empty: no threshold
  std::string threshold_help;          // its --help text
  MetricChart chart;
  int table_width = 10;                // summary table column
  std::string table_format = "%.3f";   // printf format of the mean
  // A PSNR of the frame's mean squared error: also reported as `<name>_pooled`, the PSNR of the squared error
  // pooled over all frames (pooled_psnr, docs/compare.md "Pooled PSNR").
  bool pooled = false;
  bool on_sheet = true;                // printed under each test on the contact sheet (psnr_y is not: PSNR says it)
  // Null: always measured. Otherwise whether `setup` asks for the metric, and what to add when it does not.
  bool (*enabled)(const ComparisonSetup& setup) = nullptr;
  std::string enable_hint;             // e.g. "add --flip ldr or --flip hdr"
  std::unique_ptr<FrameMeasure> (*make)(const ComparisonSetup& setup) = nullptr;
};

// Every metric compare knows, in CSV / table order.
const std::vector<MetricDefinition>& metric_registry();
// The registry entry called `name`, or null.
const MetricDefinition* find_metric(std::string_view name);
// The entries `setup` measures.
std::vector<const MetricDefinition*> enabled_metrics(const ComparisonSetup& setup);
// " dB": the unit as it follows a number in messages and pictures, or "" for a unitless metric.
std::string unit_suffix(const MetricDefinition& metric);
// The registry for people and for scripts (`compare --list-metrics`, `--list-metrics-json`): one line per metric,
// tab-separated name, label, unit, better ("higher" or "lower"); or a JSON array of objects with those keys and
// the metric's CSV columns, threshold option and chart range.
std::string metric_list_text();
std::string metric_list_json();

// --- Results -----------------------------------------------------------------------------------------------

// One test frame. PSNR is +infinity for identical images.
struct FrameMetrics {
  int frame = 0;
  double peak = 1.0;                    // the peak used for this frame
  std::size_t nonfinite_test = 0;       // pixels with a NaN/Inf in the test (excluded)
  std::size_t nonfinite_reference = 0;  // pixels with a NaN/Inf in the reference (excluded)
  std::size_t valid_pixels = 0;         // pixels that entered the metrics
  bool has_mask = false;
  double mask_fraction = 0.0;           // share of valid pixels inside the mask
  bool has_regions = false;
  std::array<std::size_t, kRegionCount> region_pixels{};  // valid pixels in each region (they sum to valid_pixels)
  // From the test file's header: `temporal:computeMs` and `temporal:ms:<pass>` (milliseconds).
  std::optional<double> compute_ms;
  std::map<std::string, double> timings_ms;
  double metrics_ms = 0.0;              // time compare spent on this frame's metrics (I/O excluded)
  std::vector<MetricSample> metrics;    // one per measured metric, in ComparisonReport::metrics order

  // The sample of `metric`, or null when it was not measured.
  const MetricSample* sample(std::string_view metric) const;
  // The sample of `metric`, added when absent (for reports assembled by hand).
  MetricSample& ensure_sample(std::string_view metric);
  // values[column] of `metric`; NaN when the metric or the value is absent.
  double value(std::string_view metric, std::size_t column = 0) const;
};

// What the compute time in a test's headers measures (docs/compare.md, "Speed"): decided from the first frame's
// `temporal:tool` and attributes. Only Method times are the cost of a reconstruction method.
enum class ComputeKind {
  Method,      // a method's own time (upsample-st, filter-phlm, morph-120hz outputs; any other tool's files)
  Render,      // written by render-gbuffer: its computeMs is the render pass (e.g. the 1-spp input of filter-phlm)
  Simulation,  // morph-120hz --perceive outputs (`temporal:perceivedWindow`): the perception simulation's time
};
// "method", "render", "simulation".
const char* compute_kind_name(ComputeKind kind);
// The kind of compute time of a file with this header.
ComputeKind compute_kind_of(const FrameMetadata& header);

struct SequenceReport {
  std::string name;
  std::string pattern;
  std::string mask_source;  // "test", "gbuffer", "reference" or empty
  std::string tool;         // `temporal:tool` of the first frame ("" when absent)
  ComputeKind compute_kind = ComputeKind::Method;
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
  bool disocclusion_tested = false;  // the G-buffer had depth and ids: flicker drops disoccluded pixels
  double peak = 1.0;
  bool peak_from_data = false;
  FlipMode flip = FlipMode::Off;
  double pixels_per_degree = kFlipDefaultPixelsPerDegree;  // FLIP's viewing condition
  std::optional<double> fps;                    // `temporal:fps` of the reference's first frame
  std::vector<std::string> metrics;             // names of the measured metrics, registry order
  int warmup_frames = 0;                        // ComparisonSetup::warmup_frames
  BootstrapOptions bootstrap;                   // ComparisonSetup::bootstrap
  std::string speed_metric = "psnr_rgb";        // ComparisonSetup::speed_metric
  bool regions = false;                         // ComparisonSetup::regions: frames carry region values
  RegionOptions region_options;                 // ComparisonSetup::region_options (a merged CSV: the defaults)
  std::vector<SequenceReport> sequences;
};

// One compared frame as the engine holds it, for observers that make pictures of it (temporal/pictures): every
// pointer is valid only during the call.
struct ComparedFrame {
  int frame = 0;
  std::size_t index = 0;                   // position in ComparisonReport::frames
  std::size_t count = 0;                   // frames in the comparison
  const Image* reference = nullptr;        // the reference's compared layer (and the mask when it lives there)
  std::span<const std::string> reference_channels;
  std::string reference_path;
  const Image* gbuffer = nullptr;          // motion (+ depth, id, and ComparisonHooks::gbuffer_layers); null without
  std::string gbuffer_path;
  struct Test {
    std::string name;                      // SequenceReport::name
    const Image* image = nullptr;          // the test's compared layer
    std::span<const std::string> channels; // its compared channels, in the reference's order
    const Image* maps = nullptr;           // the error-map image (error.R/G/B/Y, error.ssim, error.flicker, error.flip,
                                           // error.invalid); null unless kept (--error-maps or keep_maps)
    const FrameMetrics* metrics = nullptr; // this frame's row
    std::string path;
  };
  std::vector<Test> tests;                 // in ComparisonSetup::tests order
};

// Observers of a running comparison (the library never prints; the tool decides what to show): the runner's
// hooks (temporal/io/runner.h), frame_done after each frame, warnings (e.g. NaN pixels found), --verbose lines;
// and `frame`, called with the images of each frame once every test is measured (an error stops the run).
struct ComparisonHooks : RunHooks {
  ComparisonHooks() = default;
  ComparisonHooks(RunHooks base) : RunHooks(std::move(base)) {}  // NOLINT: a tool's hooks are comparison hooks
  std::function<Status(const ComparedFrame&)> frame;
  bool keep_maps = false;                   // build each test frame's error-map image for `frame`
  std::vector<std::string> gbuffer_layers;  // G-buffer layers to read too when the file has them (e.g. N)
};

// Runs the comparison. Errors: Usage (bad setup), Input (missing/corrupt files, missing layers, size or
// channel-count mismatch, empty sequence, a layer FLIP cannot read), Output (error maps not writable).
Expected<ComparisonReport> compare_sequences(const ComparisonSetup& setup, const ComparisonHooks& hooks = {});

// Every file a comparison reads (reference, test and G-buffer frames), so that the caller can refuse an output
// (CSV, JSON, chart) that would replace one of them; the engine itself refuses such error maps.
Expected<ProtectedInputs> comparison_inputs(const ComparisonSetup& setup);

// Sets the PSNR / SSIM peak from its text: a positive finite number (`peak`), or `max` (`peak_from_data`,
// idiff's rule). Errors: Usage, naming the text.
Status set_peak(const std::string& text, ComparisonSetup& setup);

// The name `compare` gives a test sequence without --names: the file name without folder, frame number and
// extension (`out/taa.####.exr` -> `taa`).
std::string sequence_name(const std::string& pattern);

// --- Summaries ---------------------------------------------------------------------------------------------

struct MetricSummary {
  std::size_t count = 0;  // frames with a value
  double mean = 0.0;      // mean of the per-frame values (+inf if any PSNR frame is +inf)
  double min = 0.0, max = 0.0;
  int min_frame = 0, max_frame = 0;
  double worst() const { return higher_is_better ? min : max; }
  bool higher_is_better = true;
};
// Summary of a metric's primary value (or of values[column]) over the frames that have one.
MetricSummary summarize(const SequenceReport& sequence, std::string_view metric, std::size_t column = 0);

// The per-frame values of a metric's primary value (or values[column]), one per frame in order, NaN where the
// frame has none.
std::vector<double> metric_series(const SequenceReport& sequence, std::string_view metric, std::size_t column = 0);

// The per-frame primary values of `metric` in `region` (kAllRegions: metric_series), NaN where a frame has none.
std::vector<double> region_series(const SequenceReport& sequence, std::string_view metric, int region);
// The pixels behind each frame's value of `region`: valid_pixels (kAllRegions) or region_pixels (0 without regions).
std::vector<double> region_weights(const SequenceReport& sequence, int region);
// The region's share of the sequence's valid pixels over all frames (1 for kAllRegions; NaN without pixels).
double region_share(const SequenceReport& sequence, int region);
// The pooled PSNR of a `pooled` metric (psnr_rgb, psnr_y) in `region`, with its block-bootstrap interval over frames
// (bootstrap_pooled_psnr), and the paired difference pooled(a) - pooled(b) with its interval.
MeanInterval pooled_summary(const SequenceReport& sequence, std::string_view metric, int region,
                            const BootstrapOptions& options);
MeanInterval pooled_difference(const SequenceReport& a, const SequenceReport& b, std::string_view metric, int region,
                               const BootstrapOptions& options);

// Mean of `temporal:computeMs` over frames that have it (else the mean sum of the `temporal:ms:*` timings).
std::optional<double> mean_compute_ms(const SequenceReport& sequence);

// Indices of the points not dominated in (lower cost, higher score): no other point has a cost <= and a score >=
// with one of them strictly better. Sorted by cost. Points with a non-finite cost or score are left out.
std::vector<std::size_t> pareto_front(const std::vector<double>& cost, const std::vector<double>& score);

// Speed against error (docs/compare.md, "Speed"): one point per sequence whose headers time the method itself
// (ComputeKind::Method: never a render's or a simulation's time) and that has a finite mean of
// `report.speed_metric`, in sequence order. `on_front`: the point is on the Pareto front of lower compute time
// against a better mean (higher or lower as the metric's registry entry says).
struct SpeedPoint {
  std::size_t sequence = 0;  // index into report.sequences
  double compute_ms = 0.0;   // mean_compute_ms
  double value = 0.0;        // mean of the speed metric
  bool on_front = false;
};
std::vector<SpeedPoint> speed_points(const ComparisonReport& report);
// Usage error unless `setup.speed_metric` is a registry metric that `setup` measures (with how to turn it on).
Status check_speed_metric(const ComparisonSetup& setup);

// The table compare prints: one line per sequence with its frame count, the mean of each measured metric, the
// pooled PSNRs (`psnr_rgb_pooled`, ...) and the mean compute time from the headers; with regions a second table, one
// line per sequence and region with its pixel share and the same columns.
std::string summary_table(const ComparisonReport& report);

// --- Thresholds (compare --fail-*) -------------------------------------------------------------------------

struct Thresholds {
  std::map<std::string, double> limits;  // metric name -> limit; fail when the judged value is worse
  bool worst_frame = false;              // judge the worst frame instead of the sequence mean
  bool nonfinite = false;                // fail when a test frame has NaN/Inf pixels or an overflowing error
};
struct ThresholdFailure {
  std::string sequence;
  std::string metric;
  double value = 0.0;
  double limit = 0.0;
  std::string text;             // the message when it is not a metric against a limit (--fail-nonfinite)
  std::string message() const;  // "taa: psnr_rgb 28.1 dB < limit 30 dB"
};
// Usage error when a limit names a metric that has no threshold or that `setup` does not measure (with how to
// turn it on).
Status check_threshold_setup(const ComparisonSetup& setup, const Thresholds& thresholds);
std::vector<ThresholdFailure> check_thresholds(const ComparisonReport& report, const Thresholds& thresholds);

// --- Shards ---------------------------------------------------------------------------------------------------

// Reads a CSV written by write_comparison_csv back into a report (per-frame values exactly as computed; the
// inputs' metadata is not in the CSV). Input error for a file that is not such a CSV.
Expected<ComparisonReport> read_comparison_csv(const std::string& path);
// Joins per-shard reports of one comparison (same metrics, same sequences in the same order, disjoint frame
// ranges) into one, frames in order. `names` (the shards' files) are for messages and the merged report's
// `reference`. The merged summaries equal a single run's exactly (docs/compare.md, "Shards").
Expected<ComparisonReport> merge_comparisons(const std::vector<ComparisonReport>& parts,
                                            const std::vector<std::string>& names = {});
// read_comparison_csv of each file, merge_comparisons, and the summary settings of `setup` (warm-up, bootstrap).
Expected<ComparisonReport> merge_comparison_csvs(const std::vector<std::string>& csvs, const ComparisonSetup& setup);

// --- Outputs (written atomically: temporary file, then rename) ---------------------------------------------

// One row per frame and test sequence; infinite PSNR is written `inf`, missing values are empty fields.
Status write_comparison_csv(const ComparisonReport& report, const std::string& path);
// Summary per sequence (mean, min, max of each metric, timings), inputs and threshold results. Infinite
// values are the string "inf", missing values null.
Status write_comparison_json(const ComparisonReport& report, const Thresholds& thresholds,
                             const std::vector<ThresholdFailure>& failures, const std::string& tool,
                             const std::string& parameters, const std::string& path);

}  // namespace temporal
