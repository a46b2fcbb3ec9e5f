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

  struct PerFrame {
    Metric metric;
    std::string suffix, title, y_label;
  };
  const std::vector<PerFrame> per_frame = {
      {Metric::PsnrRgb, "", "PSNR (" + report.layer + ") per frame", "PSNR (dB)"},
      {Metric::PsnrY, "-psnr-y", "PSNR of luminance per frame", "PSNR (dB)"},
      {Metric::Ssim, "-ssim", "SSIM of luminance per frame", "SSIM"},
      {Metric::Flicker, "-flicker",
       std::string("Temporal instability per frame") + (report.motion_compensated ? " (motion-compensated)" : ""),
       "flicker (RMS of luminance change difference)"},
  };
  for (const auto& pf : per_frame) {
    Chart c;
    c.title = pf.title + " against " + ref_name;
    c.x_label = "frame";
    c.y_label = pf.y_label;
    bool any = false;
    for (const auto& s : report.sequences) {
      ChartSeries series;
      series.name = s.name;
      for (const auto& f : s.frames) {
        const double v = metric_value(f, pf.metric);
        series.x.push_back(f.frame);
        series.y.push_back(std::isfinite(v) ? v : kNaN);  // +inf PSNR (identical frame) leaves a gap
        any = any || std::isfinite(v);
      }
      c.series.push_back(std::move(series));
    }
    if (pf.metric == Metric::Flicker && !any) continue;  // one frame: no temporal change to measure
    charts.emplace_back(stem + pf.suffix + ext, std::move(c));
  }

  Chart speed;
  speed.title = "Speed against error (mean over frames)";
  speed.x_label = "compute time per frame (ms, from temporal:computeMs / temporal:ms:*)";
  speed.y_label = "mean PSNR (" + report.layer + ", dB)";
  speed.style = ChartStyle::Points;
  for (const auto& s : report.sequences) {
    const auto ms = mean_compute_ms(s);
    const auto psnr = summarize(s, Metric::PsnrRgb);
    if (!ms || !psnr.count || !std::isfinite(psnr.mean)) continue;
    speed.series.push_back({s.name, {*ms}, {psnr.mean}});
  }
  if (!speed.series.empty()) charts.emplace_back(stem + "-speed" + ext, std::move(speed));
  return charts;
}

}  // namespace temporal
