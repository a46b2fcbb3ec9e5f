// The charts of `compare --plot` (temporal/plot/plot.h): per-frame metric curves and speed against error.
#include "temporal/metrics/comparison.h"
#include "temporal/plot/plot.h"

#include <cmath>
#include <filesystem>
#include <limits>

namespace temporal {
namespace {
namespace fs = std::filesystem;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}  // namespace

std::vector<std::pair<std::string, Chart>> comparison_charts(const ComparisonReport& report,
                                                             const std::string& plot_path) {
  const fs::path p(plot_path);
  const std::string ext = p.has_extension() ? p.extension().string() : std::string(".png");
  const std::string stem = (p.parent_path() / p.stem()).string();
  const std::string ref_name = fs::path(report.reference).filename().string();
  std::vector<std::pair<std::string, Chart>> charts;

  // One chart per measured metric, from its registry entry (temporal/metrics/comparison.h).
  for (const auto& name : report.metrics) {
    const MetricDefinition* d = find_metric(name);
    if (!d) continue;
    std::string title = d->chart.title;
    auto replace = [&](const std::string& key, const std::string& with) {
      if (const auto at = title.find(key); at != std::string::npos) title.replace(at, key.size(), with);
    };
    replace("{layer}", report.layer);
    replace("{motion}", report.motion_compensated ? " (motion-compensated)" : "");
    Chart c;
    c.title = title + " against " + ref_name;
    c.x_label = "frame";
    c.y_label = d->chart.y_label;
    bool any = false;
    for (const auto& s : report.sequences) {
      ChartSeries series;
      series.name = s.name;
      for (const auto& f : s.frames) {
        const double v = f.value(name);
        series.x.push_back(f.frame);
        series.y.push_back(std::isfinite(v) ? v : kNaN);  // +inf PSNR (identical frame) leaves a gap
        any = any || std::isfinite(v);
      }
      c.series.push_back(std::move(series));
    }
    if (d->chart.skip_without_values && !any) continue;  // e.g. one frame: no temporal change to measure
    charts.emplace_back(stem + d->chart.suffix + ext, std::move(c));
  }

  Chart speed;
  speed.title = "Speed against error (mean over frames)";
  speed.x_label = "compute time per frame (ms, from temporal:computeMs / temporal:ms:*)";
  speed.y_label = "mean PSNR (" + report.layer + ", dB)";
  speed.style = ChartStyle::Points;
  for (const auto& s : report.sequences) {
    const auto ms = mean_compute_ms(s);
    const auto psnr = summarize(s, "psnr_rgb");
    if (!ms || !psnr.count || !std::isfinite(psnr.mean)) continue;
    speed.series.push_back({s.name, {*ms}, {psnr.mean}});
  }
  if (!speed.series.empty()) charts.emplace_back(stem + "-speed" + ext, std::move(speed));
  return charts;
}

}  // namespace temporal
