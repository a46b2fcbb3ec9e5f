// The charts of `compare --plot` (temporal/plot/plot.h): per-frame metric curves and speed against error.
#include "temporal/compare/comparison.h"
#include "temporal/plot/plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>

namespace temporal {
namespace {
namespace fs = std::filesystem;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string with_title(const std::string& title, const std::string& what) {
  return title.empty() ? what : title + ": " + what;
}
}  // namespace

std::vector<std::pair<std::string, Chart>> comparison_charts(const ComparisonReport& report,
                                                             const std::string& plot_path, const std::string& title) {
  const fs::path p(plot_path);
  const std::string ext = p.has_extension() ? p.extension().string() : std::string(".png");
  const std::string stem = (p.parent_path() / p.stem()).string();
  std::string x_label = "frame number";
  if (report.fps && *report.fps > 0) {
    char text[64];
    std::snprintf(text, sizeof text, "frame number (at %g frames/s)", *report.fps);
    x_label = text;
  }
  std::vector<std::pair<std::string, Chart>> charts;

  // One chart per measured metric, from its registry entry (temporal/compare/comparison.h).
  for (const auto& name : report.metrics) {
    const MetricDefinition* d = find_metric(name);
    if (!d) continue;
    std::string what = d->chart.title;
    auto replace = [&](const std::string& key, const std::string& with) {
      if (const auto at = what.find(key); at != std::string::npos) what.replace(at, key.size(), with);
    };
    replace("{layer}", report.layer);
    replace("{motion}", report.motion_compensated ? " (motion-compensated)" : "");
    Chart c;
    c.title = with_title(title, what);
    c.x_label = x_label;
    c.y_label = d->chart.y_label;
    c.y_lowest = d->chart.lowest;
    c.y_highest = d->chart.highest;
    bool any = false;
    for (std::size_t i = 0; i < report.sequences.size(); ++i) {
      const SequenceReport& s = report.sequences[i];
      ChartSeries series;
      series.name = s.name;
      series.color = int(i);
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

  // Speed: only times that measure the method itself (ComputeKind::Method). A render-gbuffer input's computeMs
  // is the render, a morph-120hz --perceive output's the perception simulation: neither is a method's cost.
  Chart speed;
  speed.title = with_title(title, "Speed against error (mean over frames)");
  speed.x_label = "method compute time per frame (ms, temporal:computeMs, I/O excluded)";
  // A merged report (compare --merge) does not know its layer: the CSV does not carry it.
  speed.y_label = report.layer.empty() ? std::string("mean PSNR (dB)") : "mean PSNR (" + report.layer + ", dB)";
  speed.style = ChartStyle::Points;
  for (std::size_t i = 0; i < report.sequences.size(); ++i) {
    const SequenceReport& s = report.sequences[i];
    if (s.compute_kind != ComputeKind::Method) continue;
    const auto ms = mean_compute_ms(s);
    const auto psnr = summarize(s, "psnr_rgb");
    if (!ms || !psnr.count || !std::isfinite(psnr.mean)) continue;
    speed.series.push_back({s.name, {*ms}, {psnr.mean}, int(i)});  // the colour it has in the other charts
  }
  // The Pareto front of the methods (and of a sweep's parameter values): where a faster method costs PSNR.
  std::vector<double> cost, score;
  for (const auto& s : speed.series) {
    cost.push_back(s.x.front());
    score.push_back(s.y.front());
  }
  if (speed.series.size() >= 2) {
    ChartSeries front;
    front.name = "Pareto front";
    front.line = true;
    for (const std::size_t i : pareto_front(cost, score)) {
      front.x.push_back(cost[i]);
      front.y.push_back(score[i]);
    }
    speed.series.push_back(std::move(front));
  }
  if (!speed.series.empty()) charts.emplace_back(stem + "-speed" + ext, std::move(speed));
  return charts;
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

}  // namespace temporal
