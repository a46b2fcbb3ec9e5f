// Frame-by-frame comparison of test sequences against a reference (temporal/compare/comparison.h).
//
// Streaming: each frame's reference, G-buffer and test files are read, measured and dropped; what survives a
// frame is the luminance of the reference and of each test (for flicker) and the metric rows. Only the layers
// that are compared (plus `motion` and the mask) are read from the multi-part files. The engine prepares what
// several metrics share (validity, luminance, the motion-compensated change of luminance, the error-map image);
// the metrics themselves are the registry's (registry.cpp).
#include "temporal/compare/comparison.h"

#include "temporal/io/exr.h"
#include "temporal/metrics/flicker.h"
#include "temporal/core/image.h"
#include "temporal/metrics/metrics.h"
#include "temporal/core/reproject.h"
#include "temporal/io/runner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>

namespace temporal {
namespace {

namespace fs = std::filesystem;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string size_text(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

std::string safe_file_name(const std::string& name) {
  std::string out;
  for (char c : name) out += (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.') ? c : '_';
  return out.empty() ? std::string("test") : out;
}

std::string frame_file(const std::string& dir, const std::string& name, int frame) {
  return (fs::path(dir) / (safe_file_name(name) + "." + frame_digits(frame) + ".exr")).string();
}

// True when the channel list has `name` as a channel or as a layer.
bool has_layer(const std::vector<std::string>& channels, const std::string& name) {
  for (const auto& c : channels) {
    if (c == name) return true;
    const auto dot = c.rfind('.');
    if (dot != std::string::npos && c.compare(0, dot, name) == 0 && dot == name.size()) return true;
  }
  return false;
}

// The mask plane of `image` (its first channel in compared_channels order), or nullptr.
const float* mask_plane(const Image& image, const std::string& mask) {
  const auto names = compared_channels(image, mask);
  return names.empty() ? nullptr : image.plane(names.front());
}

std::vector<const float*> planes_of(const Image& image, const std::vector<std::string>& names) {
  std::vector<const float*> planes;
  for (const auto& n : names) planes.push_back(image.plane(n));
  return planes;
}

// Per-test state that lives across frames.
struct TestState {
  SequencePattern pattern;
  std::string mask_source;
  std::vector<float> y, prev_y, delta;
  bool has_prev = false;
  SequenceReport report;
  std::optional<Image> image, maps;  // this frame's test image and error maps, kept for ComparisonHooks::frame
  std::vector<std::string> channels;
  int latency = 0;                   // `temporal:latencyFrames` of the first frame (latency-aware scoring)
  std::size_t unshown = 0;           // compared frames whose reference frame + latency is not on disk
};

// A reference frame read ahead for latency-aware scoring: its compared planes and where they are finite.
struct ShownReference {
  std::optional<Image> image;        // empty: the file does not exist
  std::vector<const float*> planes;
  std::vector<std::uint8_t> finite;
};

// One comparison run: setup checks and inputs (open), then per frame the reference (reference_frame) and each
// test (test_frame).
class Run {
 public:
  Run(const ComparisonSetup& setup, const ComparisonHooks& hooks) : setup_(setup), hooks_(hooks) {}

  Expected<ComparisonReport> run() {
    if (auto st = open(); !st) return st.error();
    // The latency of each test, from its first compared frame's header (docs/conventions.md, "Latency").
    if (setup_.latency_aware)
      for (auto& t : tests_)
        if (auto st = read_latency(t); !st) return st.error();
    // A range that starts after the first frame on disk (a shard of a longer sequence) first reads the frame
    // before it, without reporting it: the first compared frame then gets the flicker value a single run over the
    // whole sequence gives it, and per-shard results merge exactly (docs/compare.md, "Shards"). The same for
    // every gap of a stepped list (--frames 0-47y3): each compared frame's flicker is its change from the frame
    // just before it, whichever frames are listed; without that frame on disk it has no flicker value (as after
    // a cut).
    // With --regions the static test looks back static_frames frames, so that many frames before each gap are
    // primed (as far as they are on disk and not compared anyway): a shard's regions equal a single run's.
    const int prime_depth = setup_.regions ? std::max(1, setup_.region_options.static_frames) : 1;
    std::vector<int> order;
    std::vector<bool> primes;
    for (std::size_t i = 0; i < report_.frames.size(); ++i) {
      const int f = report_.frames[i];
      const bool gap_before = i == 0 ? bool(setup_.frames) : report_.frames[i - 1] != f - 1;
      if (gap_before) {
        const int floor = i == 0 ? std::numeric_limits<int>::min() : report_.frames[i - 1] + 1;
        int first = f;  // the earliest frame of an unbroken run of frames on disk just before f
        while (f - first < prime_depth && first - 1 >= floor) {
          auto exists = previous_frame_exists(first - 1);
          if (!exists) return exists.error();
          if (!*exists) break;
          --first;
        }
        for (int p = first; p < f; ++p) {
          order.push_back(p);
          primes.push_back(true);
        }
      }
      order.push_back(f);
      primes.push_back(false);
    }
    std::size_t reported = 0;
    for (std::size_t fi = 0; fi < order.size(); ++fi) {
      const int frame = order[fi];
      priming_ = primes[fi];
      // No history across a gap that no primed frame fills.
      if (fi > 0 && order[fi - 1] != frame - 1) ref_has_prev_ = false;
      shown_.erase(shown_.begin(), shown_.lower_bound(frame));  // frames before this one are never shown again
      if (auto st = reference_frame(fi, frame); !st) return st.error();
      for (auto& t : tests_) {
        if (auto st = test_frame(t, fi, frame); !st) return st.error();
        if (priming_) t.report.frames.pop_back();  // history only
      }
      if (ref_invalid_ && !priming_)
        warn(ref_path_, std::to_string(ref_invalid_) + " pixels hold NaN or Inf; they are excluded from every metric");
      if (hooks_.frame && !priming_)  // the observer sees the compared frames only, indexed among them
        if (auto st = observe(reported, frame); !st) return st.error();
      for (std::size_t i = 0; i < n_; ++i)
        if (!ref_valid_[i]) ref_y_[i] = std::numeric_limits<float>::quiet_NaN();
      std::swap(ref_y_, ref_prev_y_);
      ref_has_prev_ = true;
      if (!priming_) ++reported;
      if (hooks_.frame_done && !priming_) hooks_.frame_done(frame, int(reported), int(report_.frames.size()));
    }
    priming_ = false;
    for (auto& t : tests_) {
      if (t.unshown)
        warn(t.pattern.path(report_.frames.back()),
             std::to_string(t.unshown) + " compared frames have no reference frame " + std::to_string(t.latency) +
                 " frames later (the instant they are shown, temporal:latencyFrames = " + std::to_string(t.latency) +
                 "): no psnr_latency value there; give the reference " + std::to_string(t.latency) + " more frames");
      report_.sequences.push_back(std::move(t.report));
    }
    return std::move(report_);
  }

 private:
  void log(const std::string& text) const {
    if (hooks_.log) hooks_.log(text);
  }
  void warn(const std::string& file, const std::string& text) const {
    if (hooks_.warning) hooks_.warning(file, text);
  }

  Status open();
  Status open_tests(const FrameRange& range);
  Status find_masks();
  Status reference_frame(std::size_t fi, int frame);
  Status read_latency(TestState& t);
  Expected<const ShownReference*> shown_reference(int frame);
  Status test_frame(TestState& t, std::size_t fi, int frame);
  FrameInputs inputs(TestState& t, int frame, std::span<const float* const> planes,
                     std::span<const std::string> names, const float* mask, double peak, bool change, Image* maps);
  Status write_maps(Image& maps, const Image& test, const TestState& t, const std::string& path, int frame,
                    const FrameMetrics& m);
  Status observe(std::size_t fi, int frame);
  void add_invalid_channel(Image& maps) const;

  const ComparisonSetup& setup_;
  const ComparisonHooks& hooks_;
  ComparisonReport report_;
  std::vector<const MetricDefinition*> definitions_;
  std::vector<std::unique_ptr<FrameMeasure>> measures_;
  std::optional<SequencePattern> ref_pattern_, gbuf_pattern_;
  std::vector<TestState> tests_;
  bool gbuf_mask_ = false, ref_mask_ = false;
  ProtectedInputs inputs_;  // every file this comparison reads: no error map may replace one
  bool priming_ = false;     // this frame only primes the history (the frame before a --frames range)
  // True when frame `f` of the reference, of every test and of the G-buffer exists on disk; an input error naming
  // the file when one of them cannot be examined (a symbolic link loop, a folder without search permission: the
  // throwing std::filesystem::exists would end the run with exit 5).
  Expected<bool> previous_frame_exists(int f) const {
    if (f < 0) return false;
    std::vector<std::string> paths{ref_pattern_->path(f)};
    for (const auto& t : tests_) paths.push_back(t.pattern.path(f));
    if (gbuf_pattern_) paths.push_back(gbuf_pattern_->path(f));
    for (const auto& path : paths) {
      auto found = input_exists(path);
      if (!found || !*found) return found;
    }
    return true;
  }
  bool gbuf_geometry_ = false, have_prev_geometry_ = false;  // G-buffer depth and ids for the disocclusion test
  bool gbuf_warped_ = false;  // and prevDepth.Z, the expected previous depth (temporal/core/reproject.h)
  // --regions: this frame's region of every pixel, the same as 0/1 planes, and the per-pixel count of still frames.
  std::vector<std::uint8_t> labels_;
  std::vector<std::uint16_t> still_;
  std::array<std::vector<float>, kRegionCount> region_masks_;
  std::vector<float> prev_z_;
  std::vector<std::uint32_t> prev_id_;
  ExrSelection ref_sel_, gbuf_sel_;
  // The current frame: reference and G-buffer, and the shared work planes (allocated at the first frame).
  std::optional<Image> ref_, gbuf_;
  std::string ref_path_, gbuf_path_;
  std::vector<std::string> ref_names_;
  std::vector<const float*> ref_planes_;
  std::vector<float> ref_y_, ref_prev_y_, ref_delta_, warped_;
  std::vector<std::uint8_t> ref_valid_, valid_, shown_valid_;
  std::map<int, ShownReference> shown_;  // reference frames read ahead for latency-aware scoring
  std::size_t ref_invalid_ = 0;
  bool ref_has_prev_ = false, history_ = false;
  std::size_t n_ = 0;
  int width_ = 0, height_ = 0;
};

Status Run::open() {
  if (setup_.tests.empty()) return Error::usage("no test sequence given: name at least one TEST.####.exr after --reference");
  if (!setup_.names.empty() && setup_.names.size() != setup_.tests.size())
    return Error::usage("--names has " + std::to_string(setup_.names.size()) + " names for " +
                        std::to_string(setup_.tests.size()) + " test sequences: give one name per test, comma-separated");
  if (!(setup_.peak > 0.0) || !std::isfinite(setup_.peak)) return Error::usage("--peak must be a positive number or 'max'");
  if (setup_.flip != FlipMode::Off &&
      !(setup_.flip_options.pixels_per_degree >= kFlipMinPixelsPerDegree &&
        setup_.flip_options.pixels_per_degree <= kFlipMaxPixelsPerDegree))
    return Error::usage("--ppd must be in [1, 1000] pixels per degree (FLIP's default: 67.0206; larger values ask for "
                        "filters wider than any image)");

  report_.reference = setup_.reference;
  report_.gbuffer = setup_.gbuffer;
  report_.layer = setup_.layer.empty() ? std::string("rgb") : setup_.layer;
  report_.reference_layer = setup_.reference_layer.empty() ? report_.layer : setup_.reference_layer;
  report_.mask = setup_.mask;
  report_.motion_compensated = !setup_.gbuffer.empty();
  report_.warmup_frames = setup_.warmup_frames;
  report_.bootstrap = setup_.bootstrap;
  report_.speed_metric = setup_.speed_metric;
  report_.regions = setup_.regions;
  report_.region_options = setup_.region_options;
  if (setup_.regions && setup_.gbuffer.empty())
    return Error::usage("--regions motion needs --gbuffer G.####.exr: the regions come from the G-buffer's motion, "
                        "depth and ids");
  if (setup_.region_options.static_frames < 1 || setup_.region_options.static_frames > 65535)
    return Error::usage("--static-frames must be a whole number of frames from 1 to 65535");
  if (!(setup_.region_options.static_tolerance >= 0.0) || !std::isfinite(setup_.region_options.static_tolerance))
    return Error::usage("--static-tolerance must be a finite number >= 0 (a luminance change in pixel units)");
  report_.peak = setup_.peak;
  report_.peak_from_data = setup_.peak_from_data;
  report_.flip = setup_.flip;
  report_.pixels_per_degree = setup_.flip_options.pixels_per_degree;
  definitions_ = enabled_metrics(setup_);
  for (const auto* d : definitions_) {
    report_.metrics.push_back(d->name);
    measures_.push_back(d->make(setup_));
  }

  auto ref_pattern = SequencePattern::parse(setup_.reference);
  if (!ref_pattern) return ref_pattern.error();
  ref_pattern_ = *ref_pattern;
  auto frames = resolve_frames(*ref_pattern_, setup_.frames);
  if (!frames) return frames.error();
  report_.frames = *frames;
  const FrameRange range{report_.frames.front(), report_.frames.back()};

  if (!setup_.gbuffer.empty()) {
    auto p = SequencePattern::parse(setup_.gbuffer);
    if (!p) return p.error();
    if (auto f = resolve_frames(*p, range); !f) return f.error();
    gbuf_pattern_ = *p;
  }
  if (auto st = open_tests(range); !st) return st;
  if (auto st = find_masks(); !st) return st;
  auto inputs = comparison_inputs(setup_);
  if (!inputs) return inputs.error();
  inputs_ = std::move(*inputs);
  if (!setup_.error_maps.empty())  // before any work: an error map that would replace a frame not read yet
    for (const auto& t : tests_)
      for (const int f : report_.frames)
        if (auto st = inputs_.check(frame_file(setup_.error_maps, t.report.name, f), "--error-maps"); !st) return st;
  ref_sel_ = ExrSelection{layer_items(report_.reference_layer)};
  if (ref_mask_) ref_sel_.layers.push_back(setup_.mask);
  gbuf_sel_ = ExrSelection{{"motion"}};
  if (gbuf_pattern_) {
    // With depth and ids the flicker drops disoccluded pixels by the shared rule (temporal/core/reproject.h),
    // as the methods do; a G-buffer with motion only gets the off-screen rule.
    auto info = read_exr_info(gbuf_pattern_->path(report_.frames.front()));
    if (!info) return info.error();
    const auto& c = info->channels;
    gbuf_geometry_ = std::find(c.begin(), c.end(), "depth.Z") != c.end() && std::find(c.begin(), c.end(), "id") != c.end();
    if (gbuf_geometry_) gbuf_sel_.layers.insert(gbuf_sel_.layers.end(), {"depth", "id"});
    // The warped depth (seed 000 section 3.2), when the G-buffer has it: the disocclusion test compares it.
    gbuf_warped_ = gbuf_geometry_ && std::find(c.begin(), c.end(), "prevDepth.Z") != c.end();
    if (gbuf_warped_) gbuf_sel_.layers.push_back("prevDepth");
    report_.disocclusion_tested = gbuf_geometry_;
    if (setup_.regions && !gbuf_geometry_)
      return Error::input(gbuf_pattern_->path(report_.frames.front()),
                          "has no depth.Z or no uint id channel: --regions motion needs them for the disocclusion "
                          "test (temporal/core/reproject.h); render the G-buffer with render-gbuffer, or drop --regions");
  }
  if (gbuf_mask_) gbuf_sel_.layers.push_back(setup_.mask);
  if (gbuf_pattern_ && hooks_.frame && !hooks_.gbuffer_layers.empty()) {  // what the pictures show, when present
    auto info = read_exr_info(gbuf_pattern_->path(report_.frames.front()));
    if (!info) return info.error();
    for (const auto& layer : hooks_.gbuffer_layers)
      if (has_layer(info->channels, layer) &&
          std::find(gbuf_sel_.layers.begin(), gbuf_sel_.layers.end(), layer) == gbuf_sel_.layers.end())
        gbuf_sel_.layers.push_back(layer);
  }
  return {};
}

Status Run::open_tests(const FrameRange& range) {
  for (std::size_t i = 0; i < setup_.tests.size(); ++i) {
    auto p = SequencePattern::parse(setup_.tests[i]);
    if (!p) return p.error();
    // Every frame must exist before any work is done: a missing file is reported at once.
    if (auto f = resolve_frames(*p, range); !f) return f.error();
    TestState t{*p, {}, {}, {}, {}, false, {}, {}, {}, {}};
    t.report.name = setup_.names.empty() ? sequence_name(setup_.tests[i]) : setup_.names[i];
    t.report.pattern = setup_.tests[i];
    tests_.push_back(std::move(t));
  }
  if (setup_.names.empty()) {  // make derived names unique: a/out.####.exr, b/out.####.exr -> a/out, b/out
    for (std::size_t i = 0; i < tests_.size(); ++i)
      for (std::size_t j = 0; j < tests_.size(); ++j)
        if (i != j && tests_[i].report.name == sequence_name(setup_.tests[j])) {
          const auto parent = fs::path(setup_.tests[i]).parent_path().filename().string();
          tests_[i].report.name = (parent.empty() ? std::to_string(i + 1) : parent) + "/" + sequence_name(setup_.tests[i]);
          break;
        }
  }
  return {};
}

// Where the mask comes from: the test itself (a method's debug layer), else the G-buffer, else the reference.
Status Run::find_masks() {
  if (setup_.mask.empty()) return {};
  const int first = report_.frames.front();
  std::vector<std::string> gbuf_channels, ref_channels;
  if (gbuf_pattern_) {
    auto info = read_exr_info(gbuf_pattern_->path(first));
    if (!info) return info.error();
    gbuf_channels = info->channels;
  }
  auto ref_info = read_exr_info(ref_pattern_->path(first));
  if (!ref_info) return ref_info.error();
  ref_channels = ref_info->channels;
  for (auto& t : tests_) {
    auto info = read_exr_info(t.pattern.path(first));
    if (!info) return info.error();
    if (has_layer(info->channels, setup_.mask)) t.mask_source = "test";
    else if (has_layer(gbuf_channels, setup_.mask)) t.mask_source = "gbuffer";
    else if (has_layer(ref_channels, setup_.mask)) t.mask_source = "reference";
    else
      return Error::input(t.pattern.path(first), "no mask layer '" + setup_.mask + "' in this file" +
                                                     (gbuf_pattern_ ? ", the G-buffer" : "") +
                                                     " or the reference: write it (e.g. --debug-layers) or drop --mask");
    gbuf_mask_ = gbuf_mask_ || t.mask_source == "gbuffer";
    ref_mask_ = ref_mask_ || t.mask_source == "reference";
    t.report.mask_source = t.mask_source;
    log(t.report.name + ": mask '" + setup_.mask + "' from the " + t.mask_source);
  }
  return {};
}

// The reference (and G-buffer) of a frame: size and channel checks, luminance, validity, and the previous
// luminance of the reference and of every test fetched along the motion in one pass.
Status Run::reference_frame(std::size_t fi, int frame) {
  ref_path_ = ref_pattern_->path(frame);
  auto ref = read_exr(ref_path_, ref_sel_);
  if (!ref) return ref.error();
  auto ref_names = select_layers(*ref, report_.reference_layer, ref_path_);
  if (!ref_names) return ref_names.error();
  ref_names_ = std::move(*ref_names);
  if (fi == 0) {
    width_ = ref->width();
    height_ = ref->height();
    n_ = ref->pixel_count();
    report_.width = width_;
    report_.height = height_;
    report_.reference_channels = ref_names_;
    const int window = 11;
    if (width_ < window || height_ < window)
      return Error::input(ref_path_, "image is " + size_text(width_, height_) +
                                         "; compare needs at least 11x11 pixels (the SSIM window)");
    for (auto* v : {&ref_y_, &ref_prev_y_, &ref_delta_, &warped_}) v->resize(n_);
    ref_valid_.resize(n_);
    valid_.resize(n_);
    if (setup_.regions) {
      labels_.assign(n_, std::uint8_t(kRegionDisoccluded));
      still_.assign(n_, 0);
      for (auto& m : region_masks_) m.assign(n_, 0.0f);
    }
    for (auto& t : tests_) {
      t.y.resize(n_);
      t.prev_y.resize(n_);
      t.delta.resize(n_);
    }
  } else if (ref->width() != width_ || ref->height() != height_) {
    return Error::input(ref_path_, "is " + size_text(ref->width(), ref->height()) + " but frame " +
                                       std::to_string(report_.frames.front()) + " is " + size_text(width_, height_) +
                                       "; every frame of a sequence must have one size");
  } else if (ref_names_ != report_.reference_channels) {
    return Error::input(ref_path_, "has other channels for layer '" + report_.reference_layer + "' than frame " +
                                       std::to_string(report_.frames.front()));
  }
  if (fi == 0) report_.fps = ref->metadata().fps;
  ref_ = std::move(*ref);

  gbuf_.reset();
  if (gbuf_pattern_) {
    const std::string gpath = gbuf_pattern_->path(frame);
    gbuf_path_ = gpath;
    auto g = read_exr(gpath, gbuf_sel_);
    if (!g) return g.error();
    if (g->width() != width_ || g->height() != height_)
      return Error::input(gpath, "G-buffer is " + size_text(g->width(), g->height()) + " but the reference is " +
                                     size_text(width_, height_) + "; give the G-buffer rendered at the reference's size");
    if (!g->plane("motion.X") || !g->plane("motion.Y"))
      return Error::input(gpath, "the motion layer needs float channels motion.X and motion.Y");
    if (gbuf_geometry_ && (!g->plane("depth.Z") || !g->uint_plane("id")))
      return Error::input(gpath, "has no depth.Z or no uint id while frame " + std::to_string(report_.frames.front()) +
                                     " has them; every G-buffer frame must carry the same layers");
    if (const std::size_t bad = count_non_finite_layers(*g, {"motion", "depth"}); bad > 0)
      warn(gpath, std::to_string(bad) + " pixels hold NaN or Inf in motion or depth: they have no history, so no "
                                        "flicker value");
    gbuf_ = std::move(*g);
  }
  const bool cut = (gbuf_ && gbuf_->metadata().camera_cut.value_or(false)) || ref_->metadata().camera_cut.value_or(false);
  if (cut) log("frame " + std::to_string(frame) + ": camera cut, no flicker value");

  ref_planes_ = planes_of(*ref_, ref_names_);
  luminance_plane(ref_planes_, n_, ref_y_.data());
  ref_invalid_ = finite_mask(ref_planes_, {}, n_, ref_valid_.data());
  history_ = ref_has_prev_ && !cut;
  if (history_) {
    // One motion-compensated fetch for the previous luminance of the reference and of every test (they share
    // the motion field); each test's warped history lands in its delta plane, finished in test_frame.
    std::vector<const float*> previous = {ref_prev_y_.data()};
    std::vector<float*> warped_out = {warped_.data()};
    for (auto& t : tests_) {
      previous.push_back(t.prev_y.data());
      warped_out.push_back(t.delta.data());
    }
    reproject::Frames fr;
    fr.width = width_;
    fr.height = height_;
    fr.motion_x = gbuf_ ? gbuf_->plane("motion.X") : nullptr;
    fr.motion_y = gbuf_ ? gbuf_->plane("motion.Y") : nullptr;
    if (gbuf_geometry_ && have_prev_geometry_) {
      reproject::expect_depth(fr, gbuf_->plane("depth.Z"), gbuf_warped_ ? gbuf_->plane("prevDepth.Z") : nullptr);
      fr.id = gbuf_->uint_plane("id");
      fr.prev_z = prev_z_.data();
      fr.prev_id = prev_id_.data();
    }
    reproject::warp_planes(fr, previous, warped_out);
    temporal_delta(ref_y_.data(), warped_.data(), n_, ref_delta_.data());
  }
  if (setup_.regions) {
    // Classified before this frame's geometry replaces the previous one (the disocclusion test compares them).
    RegionInputs ri;
    ri.width = width_;
    ri.height = height_;
    ri.motion_x = gbuf_->plane("motion.X");
    ri.motion_y = gbuf_->plane("motion.Y");
    ri.depth = gbuf_->plane("depth.Z");
    ri.warped_depth = gbuf_warped_ ? gbuf_->plane("prevDepth.Z") : nullptr;
    ri.id = gbuf_->uint_plane("id");
    ri.previous_depth = have_prev_geometry_ ? prev_z_.data() : nullptr;
    ri.previous_id = have_prev_geometry_ ? prev_id_.data() : nullptr;
    ri.has_previous = history_ && have_prev_geometry_;
    ri.reference_y = ref_y_.data();
    ri.previous_reference_y = ref_prev_y_.data();
    classify_regions(ri, setup_.region_options, still_, labels_);
    for (int r = 0; r < kRegionCount; ++r)
      for (std::size_t i = 0; i < n_; ++i) region_masks_[std::size_t(r)][i] = labels_[i] == r ? 1.0f : 0.0f;
  }
  if (gbuf_geometry_ && gbuf_) {  // the previous frame's geometry for the next frame's disocclusion test
    const float* z = gbuf_->plane("depth.Z");
    const std::uint32_t* id = gbuf_->uint_plane("id");
    prev_z_.assign(z, z + n_);
    prev_id_.assign(id, id + n_);
    have_prev_geometry_ = true;
  }
  return {};
}

// `temporal:latencyFrames` of the test's first compared frame: a whole number of frames >= 0 (absent: 0).
Status Run::read_latency(TestState& t) {
  const std::string path = t.pattern.path(report_.frames.front());
  auto info = read_exr_info(path);
  if (!info) return info.error();
  const auto it = info->metadata.extra.find("latencyFrames");
  if (it == info->metadata.extra.end()) return {};
  char* end = nullptr;
  const long v = std::strtol(it->second.c_str(), &end, 10);
  if (end == it->second.c_str() || *end != '\0' || v < 0 || v > 100000)
    return Error::input(path, "temporal:latencyFrames is '" + it->second +
                                  "', not a whole number of frames >= 0 (docs/conventions.md, \"Latency\")");
  t.latency = int(v);
  return {};
}

// Reference frame `frame` for latency-aware scoring, read once and kept until the comparison passes it; a
// frame that is not on disk is remembered as absent.
Expected<const ShownReference*> Run::shown_reference(int frame) {
  if (auto it = shown_.find(frame); it != shown_.end()) return &it->second;
  ShownReference& s = shown_[frame];
  const std::string path = ref_pattern_->path(frame);
  auto found = input_exists(path);  // not the throwing fs::exists: a link loop is an input error naming the file
  if (!found) return found.error();
  if (!*found) return &s;
  auto img = read_exr(path, ref_sel_);
  if (!img) return img.error();
  if (img->width() != width_ || img->height() != height_)
    return Error::input(path, "is " + size_text(img->width(), img->height()) + " but frame " +
                                  std::to_string(report_.frames.front()) + " is " + size_text(width_, height_) +
                                  "; every frame of a sequence must have one size");
  if (compared_channels(*img, report_.reference_layer) != report_.reference_channels)
    return Error::input(path, "has other channels for layer '" + report_.reference_layer + "' than frame " +
                                  std::to_string(report_.frames.front()));
  s.image = std::move(*img);
  s.planes = planes_of(*s.image, report_.reference_channels);
  s.finite.resize(n_);
  finite_mask(s.planes, {}, n_, s.finite.data());
  return &s;
}

// One test frame: checks, the shared inputs (validity, luminance, temporal change), every measure, error maps.
Status Run::test_frame(TestState& t, std::size_t fi, int frame) {
  const std::string path = t.pattern.path(frame);
  ExrSelection sel{layer_items(report_.layer)};
  if (t.mask_source == "test") sel.layers.push_back(setup_.mask);
  auto img = read_exr(path, sel);
  if (!img) return img.error();
  if (img->width() != width_ || img->height() != height_)
    return Error::input(path, "is " + size_text(img->width(), img->height()) + " but the reference " + ref_path_ +
                                  " is " + size_text(width_, height_) + "; compare images of the same size");
  auto selected = select_layers(*img, report_.layer, path);
  if (!selected) return selected.error();
  const std::vector<std::string>& names = *selected;
  if (names.size() != ref_names_.size())
    return Error::input(path, "layer '" + report_.layer + "' has " + std::to_string(names.size()) +
                                  " channels but the reference's '" + report_.reference_layer + "' has " +
                                  std::to_string(ref_names_.size()) + "; pick matching layers (--layer, --reference-layer)");
  if (fi == 0) {
    report_.channels = names;
    t.report.tool = img->metadata().tool;
    t.report.compute_kind = compute_kind_of(img->metadata());
  }
  const float* mask = nullptr;
  if (t.mask_source == "test") mask = mask_plane(*img, setup_.mask);
  else if (t.mask_source == "gbuffer") mask = mask_plane(*gbuf_, setup_.mask);
  else if (t.mask_source == "reference") mask = mask_plane(*ref_, setup_.mask);
  if (!setup_.mask.empty() && !mask)
    return Error::input(path, "mask '" + setup_.mask + "' is missing or not a float channel at this frame");

  const auto t0 = std::chrono::steady_clock::now();
  const auto planes = planes_of(*img, names);
  FrameMetrics m;
  m.frame = frame;
  m.nonfinite_test = finite_mask(planes, {}, n_, valid_.data());
  m.nonfinite_reference = ref_invalid_;
  std::size_t inside = 0;
  for (std::size_t i = 0; i < n_; ++i) {
    valid_[i] &= ref_valid_[i];
    m.valid_pixels += valid_[i];
    inside += mask && valid_[i] && mask[i] > 0.5f;
  }
  m.peak = setup_.peak;
  if (setup_.peak_from_data) {
    std::vector<const float*> all = planes;
    all.insert(all.end(), ref_planes_.begin(), ref_planes_.end());
    m.peak = idiff_peak(all, n_);
  }
  if (mask) {
    m.has_mask = true;
    m.mask_fraction = m.valid_pixels ? double(inside) / double(m.valid_pixels) : 0.0;
  }
  if (setup_.regions) {
    m.has_regions = true;
    for (std::size_t i = 0; i < n_; ++i) m.region_pixels[labels_[i]] += valid_[i];
  }
  luminance_plane(planes, n_, t.y.data());
  const bool change = history_ && t.has_prev;
  if (change) temporal_delta(t.y.data(), t.delta.data(), n_, t.delta.data());  // t.delta held the warped history

  std::optional<Image> maps;
  if (!priming_ && (!setup_.error_maps.empty() || (hooks_.frame && hooks_.keep_maps))) maps.emplace(width_, height_);
  FrameInputs in = inputs(t, frame, planes, names, mask, m.peak, change, maps ? &*maps : nullptr);
  if (setup_.latency_aware) {
    // The reference at the instant this frame is shown: frame + L (docs/conventions.md, "Latency").
    in.latency_frames = t.latency;
    if (t.latency == 0) {
      in.shown_reference = ref_planes_;
      in.shown_valid = valid_.data();
    } else {
      auto shown = shown_reference(frame + t.latency);
      if (!shown) return shown.error();
      if ((*shown)->image) {
        shown_valid_.resize(n_);
        finite_mask(planes, {}, n_, shown_valid_.data());
        for (std::size_t i = 0; i < n_; ++i) shown_valid_[i] &= (*shown)->finite[i];
        in.shown_reference = (*shown)->planes;
        in.shown_valid = shown_valid_.data();
      } else if (!priming_) {
        ++t.unshown;
      }
    }
  }
  for (std::size_t k = 0; k < measures_.size(); ++k) {
    MetricSample sample;
    sample.metric = definitions_[k]->name;
    if (auto st = measures_[k]->measure(in, sample); !st) {
      Error e = st.error();
      if (e.file.empty()) e.file = path;
      return e;
    }
    m.metrics.push_back(std::move(sample));
  }
  m.metrics_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  m.compute_ms = img->metadata().compute_ms;
  m.timings_ms = img->metadata().timings_ms;
  if (m.nonfinite_test)
    warn(path, std::to_string(m.nonfinite_test) + " pixels hold NaN or Inf; they are excluded from every metric");
  for (const auto& sample : m.metrics)
    if (!sample.values.empty() && std::isinf(sample.values.front()) && sample.values.front() < 0)
      warn(path, sample.metric + " is -inf: the test holds values so far from the reference that the squared error "
                                 "overflows (a broken output); --fail-nonfinite makes this a failure");
  if (maps && !setup_.error_maps.empty())
    if (auto st = write_maps(*maps, *img, t, path, frame, m); !st) return st;
  if (hooks_.frame && !priming_) {  // kept until every test of the frame is measured (observe)
    if (maps && setup_.error_maps.empty()) add_invalid_channel(*maps);
    t.channels = names;
    t.image = std::move(*img);
    t.maps = std::move(maps);
  }

  // Keep this frame's luminance as history; pixels that were not finite must not be compared next frame.
  for (std::size_t i = 0; i < n_; ++i)
    if (!valid_[i]) t.y[i] = std::numeric_limits<float>::quiet_NaN();
  std::swap(t.y, t.prev_y);
  t.has_prev = true;
  t.report.frames.push_back(std::move(m));
  return {};
}

FrameInputs Run::inputs(TestState& t, int frame, std::span<const float* const> planes,
                        std::span<const std::string> names, const float* mask, double peak, bool change, Image* maps) {
  FrameInputs in;
  in.frame = frame;
  in.width = width_;
  in.height = height_;
  in.test = planes;
  in.reference = ref_planes_;
  in.channels = names;
  in.test_y = t.y.data();
  in.reference_y = ref_y_.data();
  in.valid = valid_.data();
  in.mask = mask;
  in.peak = peak;
  if (setup_.regions) {
    in.regions = labels_.data();
    for (std::size_t r = 0; r < kRegionCount; ++r) in.region_masks[r] = region_masks_[r].data();
  }
  in.test_change = change ? t.delta.data() : nullptr;
  in.reference_change = change ? ref_delta_.data() : nullptr;
  in.maps = maps;
  return in;
}

void Run::add_invalid_channel(Image& maps) const {
  float* inv = maps.add_channel("error.invalid");
  for (std::size_t i = 0; i < n_; ++i) inv[i] = valid_[i] ? 0.0f : 1.0f;
}

Status Run::observe(std::size_t fi, int frame) {
  ComparedFrame cf;
  cf.frame = frame;
  cf.index = fi;
  cf.count = report_.frames.size();
  cf.reference = &*ref_;
  cf.reference_channels = ref_names_;
  cf.reference_path = ref_path_;
  cf.gbuffer = gbuf_ ? &*gbuf_ : nullptr;
  cf.gbuffer_path = gbuf_ ? gbuf_path_ : std::string();
  for (auto& t : tests_)
    cf.tests.push_back({t.report.name, t.image ? &*t.image : nullptr, t.channels, t.maps ? &*t.maps : nullptr,
                        t.report.frames.empty() ? nullptr : &t.report.frames.back(), t.pattern.path(frame)});
  Status st = hooks_.frame(cf);
  for (auto& t : tests_) {
    t.image.reset();
    t.maps.reset();
  }
  return st;
}

// The metrics' channels are in `maps` already; error.invalid and the header complete it.
Status Run::write_maps(Image& maps, const Image& test, const TestState& t, const std::string& path, int frame,
                       const FrameMetrics& m) {
  add_invalid_channel(maps);
  auto& md = maps.metadata();
  md.frame = frame;
  md.fps = test.metadata().fps;
  md.time = test.metadata().time;
  md.compute_ms = m.metrics_ms;
  md.tool = setup_.tool;
  md.parameters = setup_.parameters;
  md.extra["reference"] = ref_path_;
  md.extra["test"] = path;
  md.extra["nonFinitePixels"] = std::to_string(m.nonfinite_test);
  const std::string out = frame_file(setup_.error_maps, t.report.name, frame);
  if (Status st = inputs_.check(out, "--error-maps"); !st) return st;
  return write_exr(out, maps);
}

}  // namespace

Expected<ProtectedInputs> comparison_inputs(const ComparisonSetup& setup) {
  ProtectedInputs inputs;
  auto ref = SequencePattern::parse(setup.reference);
  if (!ref) return ref.error();
  auto frames = resolve_frames(*ref, setup.frames);
  if (!frames) return frames.error();
  std::vector<SequencePattern> patterns = {*ref};
  for (const auto& t : setup.tests) {
    auto p = SequencePattern::parse(t);
    if (!p) return p.error();
    patterns.push_back(*p);
  }
  if (!setup.gbuffer.empty()) {
    auto g = SequencePattern::parse(setup.gbuffer);
    if (!g) return g.error();
    patterns.push_back(*g);
  }
  for (const auto& p : patterns)
    for (const int f : *frames) inputs.add(p.path(f));
  return inputs;
}

std::string sequence_name(const std::string& pattern) {
  std::string name = fs::path(pattern).filename().string();
  for (const std::string ext : {".exr", ".EXR"})
    if (name.size() > ext.size() && name.compare(name.size() - ext.size(), ext.size(), ext) == 0)
      name.resize(name.size() - ext.size());
  // Drop the placeholder and the separator before it (`taa.####`, `taa_%04d`).
  auto cut = name.find('#');
  if (cut == std::string::npos) cut = name.find('%');
  if (cut != std::string::npos) {
    name.resize(cut);
    while (!name.empty() && (name.back() == '.' || name.back() == '_' || name.back() == '-')) name.pop_back();
  }
  return name.empty() ? std::string("test") : name;
}

Expected<ComparisonReport> compare_sequences(const ComparisonSetup& setup, const ComparisonHooks& hooks) {
  return Run(setup, hooks).run();
}

// ---------------------------------------------------------------------------------------------------------
// Samples, summaries and thresholds

const MetricSample* FrameMetrics::sample(std::string_view metric) const {
  for (const auto& s : metrics)
    if (s.metric == metric) return &s;
  return nullptr;
}

MetricSample& FrameMetrics::ensure_sample(std::string_view metric) {
  for (auto& s : metrics)
    if (s.metric == metric) return s;
  metrics.push_back({std::string(metric), {}, kNoValue, kNoValue, 0});
  return metrics.back();
}

double FrameMetrics::value(std::string_view metric, std::size_t column) const {
  const MetricSample* s = sample(metric);
  return s && column < s->values.size() ? s->values[column] : kNaN;
}

MetricSummary summarize(const SequenceReport& sequence, std::string_view metric, std::size_t column) {
  MetricSummary s;
  const MetricDefinition* d = find_metric(metric);
  s.higher_is_better = d ? d->higher_is_better : true;
  double sum = 0.0;
  for (const auto& f : sequence.frames) {
    const double v = f.value(metric, column);
    if (std::isnan(v)) continue;
    if (s.count == 0 || v < s.min) {
      s.min = v;
      s.min_frame = f.frame;
    }
    if (s.count == 0 || v > s.max) {
      s.max = v;
      s.max_frame = f.frame;
    }
    sum += v;
    ++s.count;
  }
  s.mean = s.count ? sum / double(s.count) : kNaN;
  if (!s.count) s.min = s.max = kNaN;
  return s;
}

std::vector<double> metric_series(const SequenceReport& sequence, std::string_view metric, std::size_t column) {
  std::vector<double> v;
  v.reserve(sequence.frames.size());
  for (const auto& f : sequence.frames) v.push_back(f.value(metric, column));
  return v;
}

std::optional<double> mean_compute_ms(const SequenceReport& sequence) {
  double sum = 0.0;
  std::size_t count = 0;
  for (const auto& f : sequence.frames)
    if (f.compute_ms) {
      sum += *f.compute_ms;
      ++count;
    }
  if (count) return sum / double(count);
  for (const auto& f : sequence.frames)
    if (!f.timings_ms.empty()) {
      for (const auto& [name, ms] : f.timings_ms) sum += ms;
      ++count;
    }
  if (count) return sum / double(count);
  return std::nullopt;
}

std::vector<std::size_t> pareto_front(const std::vector<double>& cost, const std::vector<double>& score) {
  const std::size_t n = std::min(cost.size(), score.size());
  std::vector<std::size_t> front;
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(cost[i]) || !std::isfinite(score[i])) continue;
    bool dominated = false;
    for (std::size_t j = 0; j < n && !dominated; ++j)
      dominated = j != i && std::isfinite(cost[j]) && std::isfinite(score[j]) && cost[j] <= cost[i] &&
                  score[j] >= score[i] && (cost[j] < cost[i] || score[j] > score[i]);
    if (!dominated) front.push_back(i);
  }
  std::stable_sort(front.begin(), front.end(), [&](std::size_t a, std::size_t b) { return cost[a] < cost[b]; });
  return front;
}

std::vector<SpeedPoint> speed_points(const ComparisonReport& report) {
  const MetricDefinition* d = find_metric(report.speed_metric);
  const bool higher = d ? d->higher_is_better : true;
  std::vector<SpeedPoint> points;
  for (std::size_t i = 0; i < report.sequences.size(); ++i) {
    const SequenceReport& s = report.sequences[i];
    if (s.compute_kind != ComputeKind::Method) continue;
    const auto ms = mean_compute_ms(s);
    const MetricSummary m = summarize(s, report.speed_metric);
    if (!ms || !m.count || !std::isfinite(m.mean)) continue;  // +inf PSNR (identical frames) has no place
    points.push_back({i, *ms, m.mean, false});
  }
  std::vector<double> cost, score;  // pareto_front wants a score where higher is better
  for (const SpeedPoint& p : points) {
    cost.push_back(p.compute_ms);
    score.push_back(higher ? p.value : -p.value);
  }
  for (const std::size_t k : pareto_front(cost, score)) points[k].on_front = true;
  return points;
}

Status check_speed_metric(const ComparisonSetup& setup) {
  const MetricDefinition* d = find_metric(setup.speed_metric);
  if (!d) return Error::usage("--speed-metric '" + setup.speed_metric + "' is not a metric (compare --list-metrics)");
  if (d->enabled && !d->enabled(setup))
    return Error::usage("--speed-metric " + d->name + " is not measured in this run: " + d->enable_hint);
  return Status::ok();
}

const char* compute_kind_name(ComputeKind kind) {
  switch (kind) {
    case ComputeKind::Render: return "render";
    case ComputeKind::Simulation: return "simulation";
    case ComputeKind::Method: break;
  }
  return "method";
}

ComputeKind compute_kind_of(const FrameMetadata& header) {
  if (header.tool.rfind("render-gbuffer", 0) == 0) return ComputeKind::Render;
  const auto method = header.extra.find("method");
  if (header.extra.count("perceivedWindow") || (method != header.extra.end() && method->second == "perceive"))
    return ComputeKind::Simulation;
  return ComputeKind::Method;
}

std::string ThresholdFailure::message() const {
  if (!text.empty()) return sequence + ": " + text;
  const MetricDefinition* d = find_metric(metric);
  const std::string unit = d ? unit_suffix(*d) : std::string();
  const bool higher = d ? d->higher_is_better : true;
  char text[256];
  std::snprintf(text, sizeof text, "%s: %s %.6g%s %s limit %.6g%s", sequence.c_str(), metric.c_str(), value,
                unit.c_str(), higher ? "<" : ">", limit, unit.c_str());
  return text;
}

Status set_peak(const std::string& text, ComparisonSetup& setup) {
  if (text == "max") {
    setup.peak_from_data = true;
    return {};
  }
  char* end = nullptr;
  const double peak = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0' || !(peak > 0.0) || !std::isfinite(peak))
    return Error::usage("--peak '" + text + "' is not a positive number or `max`");
  setup.peak = peak;
  setup.peak_from_data = false;
  return {};
}

Status check_threshold_setup(const ComparisonSetup& setup, const Thresholds& thresholds) {
  for (const auto& [name, limit] : thresholds.limits) {
    const MetricDefinition* d = find_metric(name);
    if (!d || d->threshold_option.empty()) return Error::usage("no threshold for a metric called '" + name + "'");
    if (d->enabled && !d->enabled(setup))
      return Error::usage("--fail-" + d->threshold_option + " judges " + name + ", which is not measured: " + d->enable_hint);
    if (!std::isfinite(limit)) return Error::usage("--fail-" + d->threshold_option + " needs a finite number");
  }
  return {};
}

std::vector<ThresholdFailure> check_thresholds(const ComparisonReport& report, const Thresholds& th) {
  std::vector<ThresholdFailure> failures;
  for (const auto& seq : report.sequences)
    for (const auto& name : report.metrics) {  // registry order: psnr_rgb, ssim, flicker, flip
      const auto limit = th.limits.find(name);
      if (limit == th.limits.end()) continue;
      const auto s = summarize(seq, name);
      if (!s.count) continue;  // no value (e.g. flicker of a one-frame sequence): nothing to judge
      const double v = th.worst_frame ? s.worst() : s.mean;
      const bool fail = s.higher_is_better ? v < limit->second : v > limit->second;
      if (fail) failures.push_back({seq.name, name, v, limit->second, {}});
    }
  if (th.nonfinite)
    for (const auto& seq : report.sequences) {
      std::size_t frames = 0, pixels = 0;
      for (const auto& f : seq.frames) {
        bool bad = f.nonfinite_test > 0;
        for (const auto& sample : f.metrics)
          bad = bad || (!sample.values.empty() && std::isinf(sample.values.front()) && sample.values.front() < 0);
        frames += bad ? 1 : 0;
        pixels += f.nonfinite_test;
      }
      if (frames > 0)
        failures.push_back({seq.name, "nonfinite", double(frames), 0.0,
                            std::to_string(frames) + " frames with NaN/Inf pixels (" + std::to_string(pixels) +
                                " pixels) or an overflowing error (--fail-nonfinite)"});
    }
  return failures;
}

}  // namespace temporal
