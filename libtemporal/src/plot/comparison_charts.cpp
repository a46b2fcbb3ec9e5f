// The charts of `compare --plot` (temporal/plot/plot.h): per-frame metric curves and speed against error.
#include "temporal/compare/comparison.h"
#include "temporal/metrics/statistics.h"
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

namespace {

using NamedCharts = std::vector<std::pair<std::string, Chart>>;

// One chart per measured metric, from its registry entry (temporal/compare/comparison.h): STEM + suffix + EXT.
void metric_charts(const ComparisonReport& report, const std::string& stem, const std::string& ext,
                   const std::string& title, const std::string& x_label, NamedCharts& charts) {
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

}

// With --regions (docs/compare.md, "Regions"): each region's share of the valid pixels per frame (F-regions), and
// PSNR (RGB) per frame in each region (F-psnr-static, F-psnr-moving, F-psnr-disoccluded), one curve per sequence.
void region_charts(const ComparisonReport& report, const std::string& stem, const std::string& ext,
                   const std::string& title, const std::string& x_label, NamedCharts& charts) {
  if (report.regions && !report.sequences.empty()) {
    Chart shares;
    shares.title = with_title(title, "Share of the pixels in each region per frame");
    shares.x_label = x_label;
    shares.y_label = "share of the valid pixels (%)";
    shares.y_lowest = 0.0;
    shares.y_highest = 100.0;
    const SequenceReport& first = report.sequences.front();  // the regions are the frames', not a method's
    for (int r = 0; r < kRegionCount; ++r) {
      ChartSeries series;
      series.name = region_name(r);
      series.color = r;
      for (const auto& f : first.frames) {
        series.x.push_back(f.frame);
        series.y.push_back(f.valid_pixels ? 100.0 * double(f.region_pixels[std::size_t(r)]) / double(f.valid_pixels)
                                          : kNaN);
      }
      shares.series.push_back(std::move(series));
    }
    charts.emplace_back(stem + "-regions" + ext, std::move(shares));
    for (int r = 0; r < kRegionCount; ++r) {
      Chart c;
      c.title = with_title(title, "PSNR (" + report.layer + ") per frame, " + region_name(r) + " pixels");
      c.x_label = x_label;
      c.y_label = "PSNR (dB)";
      for (std::size_t i = 0; i < report.sequences.size(); ++i) {
        ChartSeries series;
        series.name = report.sequences[i].name;
        series.color = int(i);
        const auto values = region_series(report.sequences[i], "psnr_rgb", r);
        for (std::size_t k = 0; k < values.size(); ++k) {
          series.x.push_back(report.sequences[i].frames[k].frame);
          series.y.push_back(std::isfinite(values[k]) ? values[k] : kNaN);  // an empty region leaves a gap
        }
        c.series.push_back(std::move(series));
      }
      charts.emplace_back(stem + "-psnr-" + region_name(r) + ext, std::move(c));
    }
  }

}

// Speed: only times that measure the method itself (ComputeKind::Method). A render-gbuffer input's computeMs is the
// render, a morph-120hz --perceive output's the perception simulation: neither is a method's cost. The points and
// their Pareto front come from speed_points (the JSON's `pareto` flags are the same).
Chart speed_chart(const ComparisonReport& report, const std::string& title) {
  Chart speed;
  speed.title = with_title(title, "Speed against error (mean over frames)");
  speed.x_label = "compute time per frame (ms; the method's own, file I/O excluded)";
  const MetricDefinition* metric = find_metric(report.speed_metric);
  const std::string label = metric && !metric->label.empty() ? metric->label : report.speed_metric;
  const std::string unit = metric ? metric->unit : std::string();
  // A merged report (compare --merge) does not know its layer: the CSV does not carry it.
  std::string axis = report.layer;
  if (!unit.empty()) axis += (axis.empty() ? "" : ", ") + unit;
  speed.y_label = "mean " + label + (axis.empty() ? std::string() : " (" + axis + ")");
  speed.style = ChartStyle::Points;
  const std::vector<SpeedPoint> points = speed_points(report);
  std::vector<const SpeedPoint*> front_points;
  for (const SpeedPoint& point : points) {
    // The colour the sequence has in the other charts.
    speed.series.push_back({report.sequences[point.sequence].name, {point.compute_ms}, {point.value}, int(point.sequence)});
    if (point.on_front) front_points.push_back(&point);
  }
  // The Pareto front of the methods (and of a sweep's parameter values): where a faster method costs quality.
  if (points.size() >= 2) {
    std::stable_sort(front_points.begin(), front_points.end(),
                     [](const SpeedPoint* a, const SpeedPoint* b) { return a->compute_ms < b->compute_ms; });
    ChartSeries front;
    front.name = "Pareto front";
    front.line = true;
    for (const SpeedPoint* point : front_points) {
      front.x.push_back(point->compute_ms);
      front.y.push_back(point->value);
    }
    speed.series.push_back(std::move(front));
  }
  // Error bars: the 95 % bootstrap interval of each mean (the JSON's ci95, docs/compare.md "Intervals"), vertical
  // for the metric and horizontal for the compute time, so that two methods whose bars overlap are not read as
  // ranked by the chart alone. A bar of zero length (one frame, a constant time) is not drawn.
  for (const SpeedPoint& point : points) {
    const SequenceReport& s = report.sequences[point.sequence];
    const MeanInterval y = bootstrap_mean(metric_series(s, report.speed_metric), report.bootstrap);
    std::vector<double> ms;
    for (const auto& f : s.frames)
      if (f.compute_ms) ms.push_back(*f.compute_ms);
    const MeanInterval x = bootstrap_mean(ms, report.bootstrap);
    const int colour = int(point.sequence);
    if (std::isfinite(y.ci.low) && std::isfinite(y.ci.high) && y.ci.high > y.ci.low)
      speed.series.push_back({"", {point.compute_ms, point.compute_ms}, {y.ci.low, y.ci.high}, colour, false, true});
    if (!ms.empty() && std::isfinite(x.ci.low) && std::isfinite(x.ci.high) && x.ci.high > x.ci.low)
      speed.series.push_back({"", {x.ci.low, x.ci.high}, {point.value, point.value}, colour, false, true});
  }
  return speed;
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

  metric_charts(report, stem, ext, title, x_label, charts);
  region_charts(report, stem, ext, title, x_label, charts);
  Chart speed = speed_chart(report, title);
  if (!speed.series.empty()) charts.emplace_back(stem + "-speed" + ext, std::move(speed));
  return charts;
}

}  // namespace temporal
