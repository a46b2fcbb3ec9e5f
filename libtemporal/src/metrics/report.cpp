// CSV, JSON and chart descriptions of a comparison (temporal/metrics/comparison.h). Formats in docs/compare.md.
#include "temporal/metrics/comparison.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>

namespace temporal {
namespace {

namespace fs = std::filesystem;

Status write_text_atomic(const std::string& path, const std::string& text) {
  std::error_code ec;
  const fs::path p(path);
  if (p.has_parent_path()) fs::create_directories(p.parent_path(), ec);
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) return Error::output(path, "cannot create the file: check that its folder exists and is writable");
    out << text;
    out.flush();
    if (!out) {
      out.close();
      fs::remove(tmp, ec);
      return Error::output(path, "cannot write the file (disk full?)");
    }
  }
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    return Error::output(path, "cannot move the temporary file into place: " + ec.message());
  }
  return {};
}

// CSV field: empty for "no value", `inf` / `-inf` for infinities, else %.*g.
std::string field(double v, int digits = 8) {
  if (std::isnan(v)) return "";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char text[64];
  std::snprintf(text, sizeof text, "%.*g", digits, v);
  return text;
}
std::string field(const std::optional<double>& v, int digits = 8) { return v ? field(*v, digits) : std::string(); }

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

}  // namespace

Status write_comparison_csv(const ComparisonReport& report, const std::string& path) {
  const bool mask = !report.mask.empty();
  std::string text =
      "frame,sequence,psnr_rgb_db,psnr_y_db,ssim,flicker,mse_rgb,peak,valid_pixels,nonfinite_test,"
      "nonfinite_reference,compute_ms,metrics_ms";
  if (mask)
    text += ",mask_fraction,psnr_rgb_in_db,psnr_rgb_out_db,psnr_y_in_db,psnr_y_out_db,ssim_in,ssim_out,flicker_in,"
            "flicker_out";
  text += "\n";
  // Frame-major: all sequences of frame N, then frame N+1 (the order compare computes them).
  std::size_t frames = 0;
  for (const auto& s : report.sequences) frames = std::max(frames, s.frames.size());
  for (std::size_t i = 0; i < frames; ++i)
    for (const auto& s : report.sequences) {
      if (i >= s.frames.size()) continue;
      const auto& f = s.frames[i];
      text += std::to_string(f.frame) + "," + csv_quote(s.name) + "," + field(f.psnr_rgb) + "," + field(f.psnr_y) +
              "," + field(f.ssim) + "," + field(f.flicker) + "," + field(f.mse_rgb) + "," + field(f.peak) + "," +
              std::to_string(f.valid_pixels) + "," + std::to_string(f.nonfinite_test) + "," +
              std::to_string(f.nonfinite_reference) + "," + field(f.compute_ms) + "," + field(f.metrics_ms, 5);
      if (mask)
        text += "," + field(f.mask_fraction) + "," + field(f.psnr_rgb_inside) + "," + field(f.psnr_rgb_outside) + "," +
                field(f.psnr_y_inside) + "," + field(f.psnr_y_outside) + "," + field(f.ssim_inside) + "," +
                field(f.ssim_outside) + "," + field(f.flicker_inside) + "," + field(f.flicker_outside);
      text += "\n";
    }
  return write_text_atomic(path, text);
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
  j["peak"] = report.peak_from_data ? json("max") : json(report.peak);
  j["mask"] = report.mask.empty() ? json(nullptr) : json(report.mask);
  j["thresholds"] = {{"psnr_rgb", jnum(thresholds.psnr)},
                     {"ssim", jnum(thresholds.ssim)},
                     {"flicker", jnum(thresholds.flicker)},
                     {"judged_on", thresholds.worst_frame ? "worst" : "mean"}};
  j["passed"] = failures.empty();
  json jf = json::array();
  for (const auto& f : failures)
    jf.push_back({{"sequence", f.sequence}, {"metric", metric_name(f.metric)}, {"value", jnum(f.value)},
                  {"limit", jnum(f.limit)}, {"message", f.message()}});
  j["failures"] = jf;

  json seqs = json::array();
  for (const auto& s : report.sequences) {
    json js;
    js["name"] = s.name;
    js["path"] = s.pattern;
    js["frames"] = s.frames.size();
    for (Metric m : {Metric::PsnrRgb, Metric::PsnrY, Metric::Ssim, Metric::Flicker})
      js[metric_name(m)] = jsummary(summarize(s, m));
    std::size_t nf_test = 0, nf_ref = 0;
    for (const auto& f : s.frames) {
      nf_test += f.nonfinite_test;
      nf_ref += f.nonfinite_reference;
    }
    js["nonfinite_pixels"] = {{"test", nf_test}, {"reference", nf_ref}};
    js["compute_ms"] = jnum(mean_compute_ms(s));
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
    if (!report.mask.empty()) {
      js["mask_source"] = s.mask_source;
      js["mask_fraction"] = jnum(mean_of(s, [](const FrameMetrics& f) { return f.mask_fraction; }));
      auto region = [&](bool inside) {
        return json{
            {"psnr_rgb", jnum(mean_of(s, [&](const FrameMetrics& f) { return inside ? f.psnr_rgb_inside : f.psnr_rgb_outside; }))},
            {"psnr_y", jnum(mean_of(s, [&](const FrameMetrics& f) { return inside ? f.psnr_y_inside : f.psnr_y_outside; }))},
            {"ssim", jnum(mean_of(s, [&](const FrameMetrics& f) { return inside ? f.ssim_inside : f.ssim_outside; }))},
            {"flicker", jnum(mean_of(s, [&](const FrameMetrics& f) {
               return (inside ? f.flicker_inside : f.flicker_outside).value_or(kNaN);
             }))}};
      };
      js["inside_mask"] = region(true);
      js["outside_mask"] = region(false);
    }
    seqs.push_back(js);
  }
  j["sequences"] = seqs;
  return write_text_atomic(path, j.dump(2) + "\n");
}

}  // namespace temporal
