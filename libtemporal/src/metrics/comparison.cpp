// Frame-by-frame comparison of test sequences against a reference (temporal/metrics/comparison.h).
//
// Streaming: each frame's reference, G-buffer and test files are read, measured and dropped; what survives a
// frame is the luminance of the reference and of each test (for flicker) and the metric rows. Only the layers
// that are compared (plus `motion` and the mask) are read from the multi-part files.
#include "temporal/metrics/comparison.h"

#include "temporal/core/exr.h"
#include "temporal/metrics/flicker.h"
#include "temporal/core/image.h"
#include "temporal/metrics/metrics.h"
#include "temporal/metrics/warp.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
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
  char digits[32];
  std::snprintf(digits, sizeof digits, "%04d", frame);
  return (fs::path(dir) / (safe_file_name(name) + "." + digits + ".exr")).string();
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

std::string suffix_of(const std::string& name) {
  const auto dot = name.rfind('.');
  return dot == std::string::npos ? name : name.substr(dot + 1);
}

// Per-test state that lives across frames.
struct TestState {
  SequencePattern pattern;
  std::string mask_source;
  std::vector<float> y, prev_y, delta;
  bool has_prev = false;
  SequenceReport report;
};

}  // namespace

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
  auto log = [&](const std::string& text) {
    if (hooks.log) hooks.log(text);
  };
  auto warn = [&](const std::string& file, const std::string& text) {
    if (hooks.warning) hooks.warning(file, text);
  };
  if (setup.tests.empty()) return Error::usage("no test sequence given: name at least one TEST.####.exr after --reference");
  if (!setup.names.empty() && setup.names.size() != setup.tests.size())
    return Error::usage("--names has " + std::to_string(setup.names.size()) + " names for " +
                        std::to_string(setup.tests.size()) + " test sequences: give one name per test, comma-separated");
  if (!(setup.peak > 0.0) || !std::isfinite(setup.peak)) return Error::usage("--peak must be a positive number or 'max'");

  ComparisonReport report;
  report.reference = setup.reference;
  report.gbuffer = setup.gbuffer;
  report.layer = setup.layer.empty() ? std::string("rgb") : setup.layer;
  report.reference_layer = setup.reference_layer.empty() ? report.layer : setup.reference_layer;
  report.mask = setup.mask;
  report.motion_compensated = !setup.gbuffer.empty();
  report.peak = setup.peak;
  report.peak_from_data = setup.peak_from_data;

  auto ref_pattern = SequencePattern::parse(setup.reference);
  if (!ref_pattern) return ref_pattern.error();
  auto frames = resolve_frames(*ref_pattern, setup.frames);
  if (!frames) return frames.error();
  report.frames = *frames;
  const FrameRange range{report.frames.front(), report.frames.back()};

  std::optional<SequencePattern> gbuf_pattern;
  if (!setup.gbuffer.empty()) {
    auto p = SequencePattern::parse(setup.gbuffer);
    if (!p) return p.error();
    if (auto f = resolve_frames(*p, range); !f) return f.error();
    gbuf_pattern = *p;
  }

  std::vector<TestState> tests;
  for (std::size_t i = 0; i < setup.tests.size(); ++i) {
    auto p = SequencePattern::parse(setup.tests[i]);
    if (!p) return p.error();
    // Every frame must exist before any work is done: a missing file is reported at once.
    if (auto f = resolve_frames(*p, range); !f) return f.error();
    TestState t{*p, {}, {}, {}, {}, false, {}};
    t.report.name = setup.names.empty() ? sequence_name(setup.tests[i]) : setup.names[i];
    t.report.pattern = setup.tests[i];
    tests.push_back(std::move(t));
  }
  if (setup.names.empty()) {  // make derived names unique: a/out.####.exr, b/out.####.exr -> a/out, b/out
    for (std::size_t i = 0; i < tests.size(); ++i)
      for (std::size_t j = 0; j < tests.size(); ++j)
        if (i != j && tests[i].report.name == sequence_name(setup.tests[j])) {
          const auto parent = fs::path(setup.tests[i]).parent_path().filename().string();
          tests[i].report.name = (parent.empty() ? std::to_string(i + 1) : parent) + "/" + sequence_name(setup.tests[i]);
          break;
        }
  }

  // Where the mask comes from: the test itself (a method's debug layer), else the G-buffer, else the reference.
  const int first = report.frames.front();
  bool gbuf_mask = false, ref_mask = false;
  if (!setup.mask.empty()) {
    std::vector<std::string> gbuf_channels, ref_channels;
    if (gbuf_pattern) {
      auto info = read_exr_info(gbuf_pattern->path(first));
      if (!info) return info.error();
      gbuf_channels = info->channels;
    }
    auto ref_info = read_exr_info(ref_pattern->path(first));
    if (!ref_info) return ref_info.error();
    ref_channels = ref_info->channels;
    for (auto& t : tests) {
      auto info = read_exr_info(t.pattern.path(first));
      if (!info) return info.error();
      if (has_layer(info->channels, setup.mask)) t.mask_source = "test";
      else if (has_layer(gbuf_channels, setup.mask)) t.mask_source = "gbuffer";
      else if (has_layer(ref_channels, setup.mask)) t.mask_source = "reference";
      else
        return Error::input(t.pattern.path(first), "no mask layer '" + setup.mask + "' in this file" +
                                                       (gbuf_pattern ? ", the G-buffer" : "") +
                                                       " or the reference: write it (e.g. --debug-layers) or drop --mask");
      gbuf_mask = gbuf_mask || t.mask_source == "gbuffer";
      ref_mask = ref_mask || t.mask_source == "reference";
      t.report.mask_source = t.mask_source;
      log(t.report.name + ": mask '" + setup.mask + "' from the " + t.mask_source);
    }
  }

  ExrSelection ref_sel{{report.reference_layer}};
  if (ref_mask) ref_sel.layers.push_back(setup.mask);
  ExrSelection gbuf_sel{{"motion"}};
  if (gbuf_mask) gbuf_sel.layers.push_back(setup.mask);

  // Work planes, allocated at the first frame and reused.
  std::vector<float> ref_y, ref_prev_y, ref_delta, warped, ssim_map, flicker_map, luma_diff;
  std::vector<std::uint8_t> ref_valid, valid;
  bool ref_has_prev = false;
  std::size_t n = 0;
  int width = 0, height = 0;

  for (std::size_t fi = 0; fi < report.frames.size(); ++fi) {
    const int frame = report.frames[fi];
    const std::string ref_path = ref_pattern->path(frame);
    auto ref = read_exr(ref_path, ref_sel);
    if (!ref) return ref.error();
    const auto ref_names = compared_channels(*ref, report.reference_layer);
    if (ref_names.empty())
      return Error::input(ref_path, "no channels for layer '" + report.reference_layer + "'; pick another --layer");
    if (fi == 0) {
      width = ref->width();
      height = ref->height();
      n = ref->pixel_count();
      report.width = width;
      report.height = height;
      report.reference_channels = ref_names;
      const int window = 11;
      if (width < window || height < window)
        return Error::input(ref_path, "image is " + size_text(width, height) +
                                          "; compare needs at least 11x11 pixels (the SSIM window)");
      for (auto* v : {&ref_y, &ref_prev_y, &ref_delta, &warped, &ssim_map, &flicker_map, &luma_diff}) v->resize(n);
      ref_valid.resize(n);
      valid.resize(n);
      for (auto& t : tests) {
        t.y.resize(n);
        t.prev_y.resize(n);
        t.delta.resize(n);
      }
    } else if (ref->width() != width || ref->height() != height) {
      return Error::input(ref_path, "is " + size_text(ref->width(), ref->height()) + " but frame " +
                                        std::to_string(report.frames.front()) + " is " + size_text(width, height) +
                                        "; every frame of a sequence must have one size");
    } else if (ref_names != report.reference_channels) {
      return Error::input(ref_path, "has other channels for layer '" + report.reference_layer + "' than frame " +
                                        std::to_string(report.frames.front()));
    }

    std::optional<Image> gbuf;
    if (gbuf_pattern) {
      const std::string gpath = gbuf_pattern->path(frame);
      auto g = read_exr(gpath, gbuf_sel);
      if (!g) return g.error();
      if (g->width() != width || g->height() != height)
        return Error::input(gpath, "G-buffer is " + size_text(g->width(), g->height()) + " but the reference is " +
                                       size_text(width, height) + "; give the G-buffer rendered at the reference's size");
      if (!g->plane("motion.X") || !g->plane("motion.Y"))
        return Error::input(gpath, "the motion layer needs float channels motion.X and motion.Y");
      gbuf = std::move(*g);
    }
    const bool cut = (gbuf && gbuf->metadata().camera_cut.value_or(false)) || ref->metadata().camera_cut.value_or(false);
    const float* mx = gbuf ? gbuf->plane("motion.X") : nullptr;
    const float* my = gbuf ? gbuf->plane("motion.Y") : nullptr;
    if (cut) log("frame " + std::to_string(frame) + ": camera cut, no flicker value");

    // Reference: luminance, validity and its own temporal change.
    const auto ref_planes = planes_of(*ref, ref_names);
    luminance_plane(ref_planes, n, ref_y.data());
    const std::size_t ref_invalid = finite_mask(ref_planes, {}, n, ref_valid.data());
    const bool history = ref_has_prev && !cut;
    if (history) {
      // One motion-compensated fetch for the previous luminance of the reference and of every test (they
      // share the motion field); each test's warped history lands in its delta plane, finished below.
      std::vector<const float*> previous = {ref_prev_y.data()};
      std::vector<float*> warped_out = {warped.data()};
      for (auto& t : tests) {
        previous.push_back(t.prev_y.data());
        warped_out.push_back(t.delta.data());
      }
      warp_bilinear(previous, width, height, mx, my, warped_out);
      temporal_delta(ref_y.data(), warped.data(), n, ref_delta.data());
    }

    for (auto& t : tests) {
      const std::string path = t.pattern.path(frame);
      ExrSelection sel{{report.layer}};
      if (t.mask_source == "test") sel.layers.push_back(setup.mask);
      auto img = read_exr(path, sel);
      if (!img) return img.error();
      if (img->width() != width || img->height() != height)
        return Error::input(path, "is " + size_text(img->width(), img->height()) + " but the reference " + ref_path +
                                      " is " + size_text(width, height) + "; compare images of the same size");
      const auto names = compared_channels(*img, report.layer);
      if (names.size() != ref_names.size())
        return Error::input(path, "layer '" + report.layer + "' has " + std::to_string(names.size()) +
                                      " channels but the reference's '" + report.reference_layer + "' has " +
                                      std::to_string(ref_names.size()) + "; pick matching layers (--layer, --reference-layer)");
      if (fi == 0) report.channels = names;
      const float* mask = nullptr;
      if (t.mask_source == "test") mask = mask_plane(*img, setup.mask);
      else if (t.mask_source == "gbuffer") mask = mask_plane(*gbuf, setup.mask);
      else if (t.mask_source == "reference") mask = mask_plane(*ref, setup.mask);
      if (!setup.mask.empty() && !mask)
        return Error::input(path, "mask '" + setup.mask + "' is missing or not a float channel at this frame");

      const auto t0 = std::chrono::steady_clock::now();
      const auto planes = planes_of(*img, names);
      FrameMetrics m;
      m.frame = frame;
      const std::size_t test_invalid = finite_mask(planes, {}, n, valid.data());
      for (std::size_t i = 0; i < n; ++i) valid[i] &= ref_valid[i];
      m.nonfinite_test = test_invalid;
      m.nonfinite_reference = ref_invalid;
      m.peak = setup.peak;
      if (setup.peak_from_data) {
        std::vector<const float*> all = planes;
        all.insert(all.end(), ref_planes.begin(), ref_planes.end());
        m.peak = idiff_peak(all, n);
      }

      const auto err = squared_error(planes, ref_planes, width, height, valid.data(), mask);
      m.valid_pixels = err.all.samples / std::max<std::size_t>(1, names.size());
      m.mse_rgb = err.all.samples ? err.all.mean() : kNaN;
      m.psnr_rgb = psnr_db(err.all, m.peak);

      luminance_plane(planes, n, t.y.data());
      const float* ty = t.y.data();
      const float* ry = ref_y.data();
      const auto err_y = squared_error({&ty, 1}, {&ry, 1}, width, height, valid.data(), mask);
      m.psnr_y = psnr_db(err_y.all, m.peak);

      SsimOptions so;
      so.peak = m.peak;
      auto s = ssim(t.y.data(), ref_y.data(), width, height, valid.data(), mask, so,
                    setup.error_maps.empty() ? nullptr : ssim_map.data());
      if (!s) return Error::input(path, s.error().message);
      m.ssim = s->mean;

      FlickerResult fl;
      const bool flick = history && t.has_prev;
      if (flick) {
        temporal_delta(t.y.data(), t.delta.data(), n, t.delta.data());  // t.delta held the warped history
        fl = flicker(t.delta.data(), ref_delta.data(), width, height, valid.data(), mask,
                     setup.error_maps.empty() ? nullptr : flicker_map.data());
        m.flicker_pixels = fl.pixels;
        if (fl.pixels) m.flicker = fl.rms();
      } else if (!setup.error_maps.empty()) {
        std::fill(flicker_map.begin(), flicker_map.end(), 0.0f);
      }

      if (mask) {
        m.has_mask = true;
        m.mask_fraction = err.all.samples ? double(err.inside.samples) / double(err.all.samples) : 0.0;
        m.psnr_rgb_inside = psnr_db(err.inside, m.peak);
        m.psnr_rgb_outside = psnr_db(err.outside, m.peak);
        m.psnr_y_inside = psnr_db(err_y.inside, m.peak);
        m.psnr_y_outside = psnr_db(err_y.outside, m.peak);
        m.ssim_inside = s->mean_inside;
        m.ssim_outside = s->mean_outside;
        if (flick && fl.pixels_inside) m.flicker_inside = fl.rms_inside();
        if (flick && fl.pixels_outside) m.flicker_outside = fl.rms_outside();
      }
      m.metrics_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      m.compute_ms = img->metadata().compute_ms;
      m.timings_ms = img->metadata().timings_ms;
      if (test_invalid)
        warn(path, std::to_string(test_invalid) + " pixels hold NaN or Inf; they are excluded from every metric");

      if (!setup.error_maps.empty()) {
        Image map(width, height);
        for (std::size_t c = 0; c < names.size(); ++c) {
          float* e = map.add_channel("error." + suffix_of(names[c]));
          const float* a = planes[c];
          const float* b = ref_planes[c];
          for (std::size_t i = 0; i < n; ++i) e[i] = valid[i] ? std::fabs(a[i] - b[i]) : 0.0f;
        }
        float* ey = map.add_channel("error.Y");
        for (std::size_t i = 0; i < n; ++i) ey[i] = valid[i] ? std::fabs(ty[i] - ry[i]) : 0.0f;
        std::copy(ssim_map.begin(), ssim_map.end(), map.add_channel("error.ssim"));
        std::copy(flicker_map.begin(), flicker_map.end(), map.add_channel("error.flicker"));
        float* inv = map.add_channel("error.invalid");
        for (std::size_t i = 0; i < n; ++i) inv[i] = valid[i] ? 0.0f : 1.0f;
        auto& md = map.metadata();
        md.frame = frame;
        md.fps = img->metadata().fps;
        md.time = img->metadata().time;
        md.compute_ms = m.metrics_ms;
        md.tool = setup.tool;
        md.parameters = setup.parameters;
        md.extra["reference"] = ref_path;
        md.extra["test"] = path;
        md.extra["nonFinitePixels"] = std::to_string(test_invalid);
        const std::string out = frame_file(setup.error_maps, t.report.name, frame);
        if (auto st = write_exr(out, map); !st) return st.error();
      }

      // Keep this frame's luminance as history; pixels that were not finite must not be compared next frame.
      for (std::size_t i = 0; i < n; ++i)
        if (!valid[i]) t.y[i] = std::numeric_limits<float>::quiet_NaN();
      std::swap(t.y, t.prev_y);
      t.has_prev = true;
      t.report.frames.push_back(std::move(m));
    }
    if (ref_invalid) warn(ref_path, std::to_string(ref_invalid) + " pixels hold NaN or Inf; they are excluded from every metric");
    for (std::size_t i = 0; i < n; ++i)
      if (!ref_valid[i]) ref_y[i] = std::numeric_limits<float>::quiet_NaN();
    std::swap(ref_y, ref_prev_y);
    ref_has_prev = true;
    if (hooks.frame_done) hooks.frame_done(frame, int(fi + 1), int(report.frames.size()));
  }
  for (auto& t : tests) report.sequences.push_back(std::move(t.report));
  return report;
}

// ---------------------------------------------------------------------------------------------------------
// Summaries and thresholds

const char* metric_name(Metric metric) {
  switch (metric) {
    case Metric::PsnrRgb: return "psnr_rgb";
    case Metric::PsnrY: return "psnr_y";
    case Metric::Ssim: return "ssim";
    case Metric::Flicker: return "flicker";
  }
  return "?";
}

bool metric_higher_is_better(Metric metric) { return metric != Metric::Flicker; }

double metric_value(const FrameMetrics& f, Metric metric) {
  switch (metric) {
    case Metric::PsnrRgb: return f.psnr_rgb;
    case Metric::PsnrY: return f.psnr_y;
    case Metric::Ssim: return f.ssim;
    case Metric::Flicker: return f.flicker.value_or(kNaN);
  }
  return kNaN;
}

MetricSummary summarize(const SequenceReport& sequence, Metric metric) {
  MetricSummary s;
  s.higher_is_better = metric_higher_is_better(metric);
  double sum = 0.0;
  for (const auto& f : sequence.frames) {
    const double v = metric_value(f, metric);
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

std::string ThresholdFailure::message() const {
  char text[256];
  const bool db = metric == Metric::PsnrRgb || metric == Metric::PsnrY;
  std::snprintf(text, sizeof text, "%s: %s %.6g%s %s limit %.6g%s", sequence.c_str(), metric_name(metric), value,
                db ? " dB" : "", metric_higher_is_better(metric) ? "<" : ">", limit, db ? " dB" : "");
  return text;
}

std::vector<ThresholdFailure> check_thresholds(const ComparisonReport& report, const Thresholds& th) {
  std::vector<ThresholdFailure> failures;
  for (const auto& seq : report.sequences) {
    auto judge = [&](Metric metric, const std::optional<double>& limit) {
      if (!limit) return;
      const auto s = summarize(seq, metric);
      if (!s.count) return;  // no value (e.g. flicker of a one-frame sequence): nothing to judge
      const double v = th.worst_frame ? s.worst() : s.mean;
      const bool fail = s.higher_is_better ? v < *limit : v > *limit;
      if (fail) failures.push_back({seq.name, metric, v, *limit});
    };
    judge(Metric::PsnrRgb, th.psnr);
    judge(Metric::Ssim, th.ssim);
    judge(Metric::Flicker, th.flicker);
  }
  return failures;
}

}  // namespace temporal
