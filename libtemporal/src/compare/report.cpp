// CSV, JSON and chart descriptions of a comparison (temporal/compare/comparison.h). Formats in docs/compare.md.
#include "temporal/compare/comparison.h"

#include "temporal/io/atomic_file.h"

#include <nlohmann/json.hpp>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>

namespace temporal {
namespace {

namespace fs = std::filesystem;

// CSV field: empty for "no value", `inf` / `-inf` for infinities, else the shortest text that reads back as the
// same double (std::to_chars): per-shard CSVs then merge into exactly the single run's means (read_comparison_csv).
// `digits` > 0 rounds instead (timings, whose last digits mean nothing).
std::string field(double v, int digits = 0) {
  if (std::isnan(v)) return "";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char text[64];
  if (digits > 0) {
    std::snprintf(text, sizeof text, "%.*g", digits, v);
    return text;
  }
  const auto r = std::to_chars(text, text + sizeof text, v);
  return std::string(text, r.ptr);
}
std::string field(const std::optional<double>& v, int digits = 0) { return v ? field(*v, digits) : std::string(); }

std::string csv_quote(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

// JSON number, or "inf" / "-inf" (JSON has no infinity), or null (no value).
nlohmann::ordered_json jnum(double v) {
  if (std::isnan(v)) return nullptr;
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  return v;
}
nlohmann::ordered_json jnum(const std::optional<double>& v) { return v ? jnum(*v) : nlohmann::ordered_json(nullptr); }

nlohmann::ordered_json jsummary(const MetricSummary& s) {
  if (!s.count) return nullptr;
  return {{"mean", jnum(s.mean)},       {"min", jnum(s.min)},           {"max", jnum(s.max)},
          {"min_frame", s.min_frame},   {"max_frame", s.max_frame},     {"frames", s.count}};
}

// Mean over frames of a per-frame value (NaN skipped), NaN when none.
template <typename Get>
double mean_of(const SequenceReport& seq, Get get) {
  double sum = 0.0;
  std::size_t n = 0;
  for (const auto& f : seq.frames) {
    const double v = get(f);
    if (std::isnan(v)) continue;
    sum += v;
    ++n;
  }
  return n ? sum / double(n) : std::numeric_limits<double>::quiet_NaN();
}

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Mean of the values that are not NaN (as summarize: +inf stays +inf), NaN when none.
double series_mean(const std::vector<double>& v) {
  double sum = 0.0;
  std::size_t n = 0;
  for (const double x : v)
    if (!std::isnan(x)) {
      sum += x;
      ++n;
    }
  return n ? sum / double(n) : kNaN;
}

// The measured metrics' definitions, in report order.
std::vector<const MetricDefinition*> definitions_of(const ComparisonReport& report) {
  std::vector<const MetricDefinition*> out;
  for (const auto& name : report.metrics)
    if (const MetricDefinition* d = find_metric(name)) out.push_back(d);
  return out;
}

// The CSV layout (docs/compare.md, "Outputs"): the historical metrics' primary columns, their other columns,
// the frame's facts, the mask columns of the historical metrics, then every other metric's columns and its mask
// columns. Each cell is a function of the sequence and frame.
// Each cell is a function of the sequence, the frame and the row's region (kAllRegions, or one region of
// --regions: such a row holds the metrics' primary values over the region and the region's pixels; the columns that
// have no region value stay empty).
struct CsvColumn {
  std::string header;
  std::function<std::string(const SequenceReport&, const FrameMetrics&, int)> cell;
};

std::vector<CsvColumn> csv_layout(const ComparisonReport& report) {
  const auto defs = definitions_of(report);
  const bool mask = !report.mask.empty();
  std::vector<CsvColumn> cols;
  cols.push_back({"frame", [](const SequenceReport&, const FrameMetrics& f, int) { return std::to_string(f.frame); }});
  cols.push_back({"sequence", [](const SequenceReport& s, const FrameMetrics&, int) { return csv_quote(s.name); }});
  if (report.regions) {
    cols.push_back({"region", [](const SequenceReport&, const FrameMetrics&, int r) {
                      return std::string(region_name(r));
                    }});
    cols.push_back({"region_share", [](const SequenceReport&, const FrameMetrics& f, int r) {
                      if (r == kAllRegions) return field(1.0);
                      if (!f.valid_pixels) return field(kNaN);
                      return field(double(f.region_pixels[std::size_t(r)]) / double(f.valid_pixels));
                    }});
  }
  auto value = [&](const MetricDefinition* d, std::size_t k) {
    return CsvColumn{d->columns[k].csv, [name = d->name, k](const SequenceReport&, const FrameMetrics& f, int r) {
                       if (r == kAllRegions) return field(f.value(name, k));
                       const MetricSample* s = f.sample(name);
                       return field(s && k == 0 ? s->regions[std::size_t(r)] : kNaN);
                     }};
  };
  auto inside_outside = [&](const MetricDefinition* d) {
    for (const bool in : {true, false})
      cols.push_back({d->mask_columns[in ? 0 : 1],
                      [name = d->name, in](const SequenceReport&, const FrameMetrics& f, int r) {
                        const MetricSample* s = r == kAllRegions ? f.sample(name) : nullptr;  // the mask: whole rows
                        return field(s ? (in ? s->inside : s->outside) : kNaN);
                      }});
  };
  for (const auto* d : defs)
    if (d->historical_csv) cols.push_back(value(d, 0));
  for (const auto* d : defs)
    if (d->historical_csv)
      for (std::size_t k = 1; k < d->columns.size(); ++k) cols.push_back(value(d, k));
  cols.push_back({"peak", [](const SequenceReport&, const FrameMetrics& f, int) { return field(f.peak); }});
  cols.push_back({"valid_pixels", [](const SequenceReport&, const FrameMetrics& f, int r) {
                    return std::to_string(r == kAllRegions ? f.valid_pixels : f.region_pixels[std::size_t(r)]);
                  }});
  // Facts of the whole frame: on its `all` row only.
  auto whole = [](std::function<std::string(const FrameMetrics&)> get) {
    return [get](const SequenceReport&, const FrameMetrics& f, int r) {
      return r == kAllRegions ? get(f) : std::string();
    };
  };
  cols.push_back({"nonfinite_test", whole([](const FrameMetrics& f) { return std::to_string(f.nonfinite_test); })});
  cols.push_back(
      {"nonfinite_reference", whole([](const FrameMetrics& f) { return std::to_string(f.nonfinite_reference); })});
  cols.push_back({"compute_ms", whole([](const FrameMetrics& f) { return field(f.compute_ms, 8); })});
  cols.push_back({"metrics_ms", whole([](const FrameMetrics& f) { return field(f.metrics_ms, 5); })});
  if (mask) {
    cols.push_back({"mask_fraction", whole([](const FrameMetrics& f) { return field(f.mask_fraction); })});
    for (const auto* d : defs)
      if (d->historical_csv) inside_outside(d);
  }
  for (const auto* d : defs) {
    if (d->historical_csv) continue;
    for (std::size_t k = 0; k < d->columns.size(); ++k) cols.push_back(value(d, k));
    if (mask) inside_outside(d);
  }
  return cols;
}

}  // namespace

Status write_comparison_csv(const ComparisonReport& report, const std::string& path) {
  const auto cols = csv_layout(report);
  std::string text;
  for (std::size_t c = 0; c < cols.size(); ++c) {
    if (c) text += ',';
    text += cols[c].header;
  }
  text += "\n";
  // Frame-major: all sequences of frame N, then frame N+1 (the order compare computes them); with regions each
  // sequence's `all` row, then its static, moving and disoccluded rows.
  std::size_t frames = 0;
  for (const auto& s : report.sequences) frames = std::max(frames, s.frames.size());
  const int last_region = report.regions ? kRegionCount - 1 : kAllRegions;
  for (std::size_t i = 0; i < frames; ++i)
    for (const auto& s : report.sequences) {
      if (i >= s.frames.size()) continue;
      for (int r = kAllRegions; r <= last_region; ++r) {
        for (std::size_t c = 0; c < cols.size(); ++c) {
          if (c) text += ',';
          text += cols[c].cell(s, s.frames[i], r);
        }
        text += "\n";
      }
    }
  return write_text_atomic(path, text);
}

namespace {

// A metric's JSON summary: the primary value's {mean, min, max, min_frame, max_frame, frames}, and the mean over
// frames of each other column that names a JSON key.
nlohmann::ordered_json jinterval(const Interval& ci) { return nlohmann::ordered_json::array({jnum(ci.low), jnum(ci.high)}); }

// Mean, interval and counts of part of a series (temporal/metrics/statistics.h).
nlohmann::ordered_json jmean(std::span<const double> series, const BootstrapOptions& o) {
  const MeanInterval m = bootstrap_mean(series, o);
  nlohmann::ordered_json j = {{"frames", m.count}, {"mean", jnum(m.mean)}, {"ci95", jinterval(m.ci)}};
  if (m.infinite) j["infinite_frames"] = m.infinite;
  return j;
}

nlohmann::ordered_json metric_json(const ComparisonReport& report, const SequenceReport& s, const MetricDefinition& d) {
  auto j = jsummary(summarize(s, d.name));
  if (j.is_null()) return j;
  // Intervals: the whole sequence, and with --warmup the steady state apart from the warm-up frames.
  const auto series = metric_series(s, d.name);
  const auto all = jmean(series, report.bootstrap);
  j["ci95"] = all["ci95"];
  if (all.contains("infinite_frames")) j["infinite_frames"] = all["infinite_frames"];
  const std::size_t warm = std::min(series.size(), std::size_t(std::max(0, report.warmup_frames)));
  if (warm > 0) {
    j["warmup"] = jmean(std::span<const double>(series).first(warm), report.bootstrap);
    j["steady"] = jmean(std::span<const double>(series).subspan(warm), report.bootstrap);
  }
  for (std::size_t k = 1; k < d.columns.size(); ++k)
    if (!d.columns[k].json.empty())
      j[d.columns[k].json] = jnum(mean_of(s, [&](const FrameMetrics& f) { return f.value(d.name, k); }));
  return j;
}

// The pooled PSNR of `metric` in `region` (pooled_summary): the value over all pixels of all frames, its 95 %
// block-bootstrap interval and the frames that entered it.
nlohmann::ordered_json pooled_json(const SequenceReport& s, const std::string& metric, int region,
                                   const BootstrapOptions& o) {
  const MeanInterval m = pooled_summary(s, metric, region, o);
  if (m.count == 0) return nullptr;
  return {{"value", jnum(m.mean)}, {"ci95", jinterval(m.ci)}, {"frames", m.count}};
}

// Each region of --regions: its share of the valid pixels over all frames, and per metric the mean over frames of
// the region's per-frame values with its interval (and the pooled PSNR of the pooled metrics).
nlohmann::ordered_json regions_json(const ComparisonReport& report, const SequenceReport& s) {
  using json = nlohmann::ordered_json;
  json regions = json::object();
  for (int r = 0; r < kRegionCount; ++r) {
    json jr;
    jr["share"] = jnum(region_share(s, r));
    double pixels = 0.0;
    for (const double w : region_weights(s, r)) pixels += w;
    jr["pixels"] = std::size_t(pixels);
    for (const auto* d : definitions_of(report)) {
      const auto series = region_series(s, d->name, r);
      jr[d->name] = jmean(series, report.bootstrap);
      if (d->pooled) jr[d->name + "_pooled"] = pooled_json(s, d->name, r, report.bootstrap);
    }
    regions[region_name(r)] = jr;
  }
  return regions;
}

// `on_front`: the sequence is on the Pareto front of compute time against report.speed_metric (speed_points).
nlohmann::ordered_json sequence_json(const ComparisonReport& report, const SequenceReport& s, bool on_front) {
  using json = nlohmann::ordered_json;
  json js;
  js["name"] = s.name;
  js["path"] = s.pattern;
  js["frames"] = s.frames.size();
  const auto defs = definitions_of(report);
  for (const auto* d : defs) {
    js[d->name] = metric_json(report, s, *d);
    if (d->pooled) js[d->name + "_pooled"] = pooled_json(s, d->name, kAllRegions, report.bootstrap);
  }
  std::size_t nf_test = 0, nf_ref = 0;
  for (const auto& f : s.frames) {
    nf_test += f.nonfinite_test;
    nf_ref += f.nonfinite_reference;
  }
  js["nonfinite_pixels"] = {{"test", nf_test}, {"reference", nf_ref}};
  js["compute_ms"] = jnum(mean_compute_ms(s));
  js["compute_kind"] = compute_kind_name(s.compute_kind);
  js["pareto"] = on_front;
  js["tool"] = s.tool.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(s.tool);
  json timings = json::object();
  std::map<std::string, std::pair<double, std::size_t>> sums;
  for (const auto& f : s.frames)
    for (const auto& [name, ms] : f.timings_ms) {
      sums[name].first += ms;
      sums[name].second += 1;
    }
  for (const auto& [name, sum] : sums) timings[name] = sum.first / double(sum.second);
  js["timings_ms"] = timings;
  js["metrics_ms"] = jnum(mean_of(s, [](const FrameMetrics& f) { return f.metrics_ms; }));
  if (report.regions) js["regions"] = regions_json(report, s);
  if (!report.mask.empty()) {
    js["mask_source"] = s.mask_source;
    js["mask_fraction"] = jnum(mean_of(s, [](const FrameMetrics& f) { return f.mask_fraction; }));
    for (const bool inside : {true, false}) {
      json region;
      for (const auto* d : defs)
        region[d->name] = jnum(mean_of(s, [&](const FrameMetrics& f) {
          const MetricSample* m = f.sample(d->name);
          return m ? (inside ? m->inside : m->outside) : kNaN;
        }));
      js[inside ? "inside_mask" : "outside_mask"] = region;
    }
  }
  return js;
}

// The paired difference a - b of every two test sequences for every metric, over the frames where both have a
// value, with its interval (and the steady state apart with --warmup): the numbers behind an "A beats B".
// Pooled metrics add a `<name>_pooled` entry (pooled(a) - pooled(b), pooled_difference); with --regions every
// entry is repeated per region (`region`: "all" for the whole frame).
nlohmann::ordered_json paired_json(const ComparisonReport& report) {
  using json = nlohmann::ordered_json;
  json pairs = json::array();
  const int last_region = report.regions ? kRegionCount - 1 : kAllRegions;
  for (std::size_t a = 0; a < report.sequences.size(); ++a)
    for (std::size_t b = a + 1; b < report.sequences.size(); ++b)
      for (int r = kAllRegions; r <= last_region; ++r)
      for (const auto* d : definitions_of(report)) {
        const SequenceReport &A = report.sequences[a], &B = report.sequences[b];
        const auto sa = region_series(A, d->name, r), sb = region_series(B, d->name, r);
        const MeanInterval m = bootstrap_paired_difference(sa, sb, report.bootstrap);
        if (m.count == 0) continue;
        if (d->pooled) {
          const MeanInterval pm = pooled_difference(A, B, d->name, r, report.bootstrap);
          if (pm.count)
            pairs.push_back({{"a", A.name}, {"b", B.name}, {"metric", d->name + "_pooled"}, {"region", region_name(r)},
                             {"higher_is_better", true}, {"frames", pm.count}, {"difference", jnum(pm.mean)},
                             {"ci95", jinterval(pm.ci)}});
        }
        json p = {{"a", A.name}, {"b", B.name}, {"metric", d->name}, {"region", region_name(r)},
                  {"higher_is_better", d->higher_is_better}, {"frames", m.count}, {"mean_difference", jnum(m.mean)},
                  {"ci95", jinterval(m.ci)}};
        const std::size_t warm = std::min(sa.size(), std::size_t(std::max(0, report.warmup_frames)));
        if (warm > 0) {
          const MeanInterval st = bootstrap_paired_difference(std::span<const double>(sa).subspan(warm),
                                                              std::span<const double>(sb).subspan(warm), report.bootstrap);
          p["steady"] = {{"frames", st.count}, {"mean_difference", jnum(st.mean)}, {"ci95", jinterval(st.ci)}};
        }
        pairs.push_back(std::move(p));
      }
  return pairs;
}

}  // namespace

const char* flip_mode_name(FlipMode mode) {
  return mode == FlipMode::Ldr ? "ldr" : mode == FlipMode::Hdr ? "hdr" : "off";
}

Status write_comparison_json(const ComparisonReport& report, const Thresholds& thresholds,
                             const std::vector<ThresholdFailure>& failures, const std::string& tool,
                             const std::string& parameters, const std::string& path) {
  using json = nlohmann::ordered_json;
  json j;
  j["tool"] = tool;
  j["parameters"] = parameters;
  j["reference"] = report.reference;
  j["gbuffer"] = report.gbuffer.empty() ? json(nullptr) : json(report.gbuffer);
  j["layer"] = report.layer;
  j["reference_layer"] = report.reference_layer;
  j["channels"] = report.channels;
  j["reference_channels"] = report.reference_channels;
  j["width"] = report.width;
  j["height"] = report.height;
  j["frames"] = {{"first", report.frames.empty() ? 0 : report.frames.front()},
                 {"last", report.frames.empty() ? 0 : report.frames.back()},
                 {"count", report.frames.size()}};
  j["motion_compensated"] = report.motion_compensated;
  j["disocclusion_tested"] = report.disocclusion_tested;
  j["peak"] = report.peak_from_data ? json("max") : json(report.peak);
  j["mask"] = report.mask.empty() ? json(nullptr) : json(report.mask);
  if (report.flip != FlipMode::Off)
    j["flip"] = {{"mode", flip_mode_name(report.flip)}, {"pixels_per_degree", report.pixels_per_degree}};
  j["speed_metric"] = report.speed_metric;
  if (report.regions)
    j["regions"] = {{"kind", "motion"},
                    {"static_frames", report.region_options.static_frames},
                    {"static_tolerance", report.region_options.static_tolerance},
                    {"static_motion", kStaticMotion}};
  else
    j["regions"] = nullptr;  // the metric of the sequences' `pareto` flags
  json th = json::object();
  for (const auto* d : definitions_of(report)) {
    if (d->threshold_option.empty()) continue;
    const auto limit = thresholds.limits.find(d->name);
    th[d->name] = limit == thresholds.limits.end() ? json(nullptr) : jnum(limit->second);
  }
  th["judged_on"] = thresholds.worst_frame ? "worst" : "mean";
  j["thresholds"] = th;
  j["passed"] = failures.empty();
  json jf = json::array();
  for (const auto& f : failures)
    jf.push_back({{"sequence", f.sequence}, {"metric", f.metric}, {"value", jnum(f.value)},
                  {"limit", jnum(f.limit)}, {"message", f.message()}});
  j["failures"] = jf;
  json seqs = json::array();
  std::vector<bool> on_front(report.sequences.size(), false);
  for (const SpeedPoint& p : speed_points(report)) on_front[p.sequence] = p.on_front;
  for (std::size_t i = 0; i < report.sequences.size(); ++i) seqs.push_back(sequence_json(report, report.sequences[i], on_front[i]));
  j["sequences"] = seqs;
  j["paired"] = paired_json(report);
  return write_text_atomic(path, j.dump(2) + "\n");
}

std::string summary_table(const ComparisonReport& report) {
  auto cell = [](double v, const std::string& format) {
    if (std::isnan(v)) return std::string("-");
    if (std::isinf(v)) return std::string(v > 0 ? "inf" : "-inf");
    char text[64];
    std::snprintf(text, sizeof text, format.c_str(), v);
    return std::string(text);
  };
  std::string out;
  auto put = [&](const std::string& text, int width, bool left) {  // printf's %-Ns / %Ns, after a space
    if (!out.empty() && out.back() != '\n') out += ' ';
    const std::size_t w = std::size_t(width), pad = text.size() < w ? w - text.size() : 0;
    if (!left) out.append(pad, ' ');
    out += text;
    if (left) out.append(pad, ' ');
  };
  const auto defs = definitions_of(report);
  std::vector<const MetricDefinition*> pooled;
  for (const auto* d : defs)
    if (d->pooled) pooled.push_back(d);
  auto pooled_width = [](const MetricDefinition* d) { return int(d->name.size() + 7); };
  put("sequence", 20, true);
  put("frames", 7, false);
  for (const auto* d : defs) put(d->name, d->table_width, false);
  put("compute_ms", 11, false);  // the columns before it as they always were (scripts read them by position)
  for (const auto* d : pooled) put(d->name + "_pooled", pooled_width(d), false);
  out += '\n';
  for (const auto& s : report.sequences) {
    put(s.name, 20, true);
    put(std::to_string(s.frames.size()), 7, false);
    for (const auto* d : defs) put(cell(summarize(s, d->name).mean, d->table_format), d->table_width, false);
    const auto ms = mean_compute_ms(s);
    put(ms ? cell(*ms, "%.3f") : std::string("-"), 11, false);
    for (const auto* d : pooled)
      put(cell(pooled_psnr(metric_series(s, d->name), region_weights(s, kAllRegions)), d->table_format),
          pooled_width(d), false);
    out += '\n';
  }
  if (!report.regions) return out;
  // Per region: the pixel share and the mean over frames of each metric's region values, then the pooled PSNRs.
  out += '\n';
  put("sequence", 20, true);
  put("region", 11, true);
  put("share", 7, false);
  for (const auto* d : defs) put(d->name, d->table_width, false);
  for (const auto* d : pooled) put(d->name + "_pooled", pooled_width(d), false);
  out += '\n';
  for (const auto& s : report.sequences)
    for (int r = 0; r < kRegionCount; ++r) {
      put(s.name, 20, true);
      put(region_name(r), 11, true);
      put(cell(100.0 * region_share(s, r), "%.1f%%"), 7, false);
      for (const auto* d : defs)
        put(cell(series_mean(region_series(s, d->name, r)), d->table_format), d->table_width, false);
      for (const auto* d : pooled)
        put(cell(pooled_psnr(region_series(s, d->name, r), region_weights(s, r)), d->table_format), pooled_width(d),
            false);
      out += '\n';
    }
  return out;
}

}  // namespace temporal
