// Charts (VTK) as PNG, SVG or PDF, behind a header that does not include VTK: only `compare` links the
// `temporal::plot` target, which keeps libGL (pulled in by VTK) out of every other program (docs/building.md,
// OSMesa trap).
//
// Debian's VTK renders through X11 only. VirtualDisplay provides a display when none is usable: it starts
// `Xvfb -displayfd N -nolisten tcp` on a free display number and points $DISPLAY at it for this process.
#pragma once

#include "temporal/core/error.h"
#include "temporal/compare/comparison.h"

#include <optional>
#include <string>
#include <sys/types.h>
#include <vector>

namespace temporal {

// One curve (or set of markers) of a chart. A NaN or infinite y leaves a gap (e.g. an infinite PSNR).
struct ChartSeries {
  std::string name;  // legend entry
  std::vector<double> x;
  std::vector<double> y;
  int color = -1;    // palette entry (Okabe-Ito, colour-blind safe); -1: the series' position. A method keeps its colour across charts
  bool line = false;  // in a Points chart: drawn as a grey line without markers (the Pareto front of the speed chart)
  // In a Points chart: one error bar (a two-point segment) in the colour of `color`, without markers and left
  // out of the legend (the 95 % intervals of the speed chart).
  bool error_bar = false;
};

enum class ChartStyle {
  Lines,   // polyline through the points with small markers (per-frame metric curves)
  Points,  // markers only (speed against error: one point per method)
};

// Everything a chart shows. Axis ranges are automatic unless given. The legend sits to the right of the plot
// area, outside it, so it never hides a curve and needs no headroom.
struct Chart {
  std::string title;
  std::string x_label;  // with the unit, e.g. "time (s)"
  std::string y_label;  // with the unit, e.g. "PSNR (dB)"
  std::vector<ChartSeries> series;
  ChartStyle style = ChartStyle::Lines;
  int width = 1280;  // size in pixels (PNG) or points (SVG, PDF)
  int height = 720;
  std::optional<double> y_min;  // fixed ends of the y axis
  std::optional<double> y_max;
  // The values the quantity can take (SSIM <= 1, FLIP in [0, 1]): the automatic range stops there.
  std::optional<double> y_lowest;
  std::optional<double> y_highest;
};

// The formats of write_chart, chosen by the file's extension.
enum class ChartFormat { Png, Svg, Pdf };
// `.png`, `.svg` or `.pdf` (any case); a Usage error naming the three for any other extension or none.
Expected<ChartFormat> chart_format(const std::string& path);

struct AxisRange {
  double low = 0.0;
  double high = 1.0;
};
// The y range `chart` is drawn with: y_min / y_max when given; otherwise the finite values' range with a 5 %
// margin (a flat series gets +-10 % of its value, at least 1e-3), never past y_lowest / y_highest.
AxisRange chart_y_range(const Chart& chart);

// Renders `chart` off screen and writes it by the extension of `path` (chart_format): an 8-bit RGB PNG, or a
// vector SVG (GL2PS) or PDF (VTK's PDF exporter) with its text as text. Written atomically (temporary file, then
// rename). Needs an X display (see VirtualDisplay). Errors: Usage for an empty chart or another extension,
// Output when the file cannot be written.
Status write_chart(const Chart& chart, const std::string& path);

// An X display for VTK for as long as this object lives.
class VirtualDisplay {
 public:
  // Keeps $DISPLAY when it is set and an X server answers there. Otherwise starts Xvfb (searched in PATH) on
  // the first free display number (`-displayfd`, so there is no race on the number), without TCP, and sets
  // $DISPLAY for this process; the server is stopped by the destructor, and dies with this process if it is
  // killed (PR_SET_PDEATHSIG). Error (Output) when no display is usable and Xvfb is absent or fails to start;
  // the message says how to fix it.
  static Expected<VirtualDisplay> ensure();

  VirtualDisplay(VirtualDisplay&& other) noexcept;
  VirtualDisplay& operator=(VirtualDisplay&& other) noexcept;
  VirtualDisplay(const VirtualDisplay&) = delete;
  VirtualDisplay& operator=(const VirtualDisplay&) = delete;
  ~VirtualDisplay();

  // True when this object started Xvfb.
  bool started() const { return pid_ > 0; }
  // The display in use, e.g. ":0" or ":2".
  const std::string& display() const { return display_; }

 private:
  VirtualDisplay() = default;
  void stop();
  pid_t pid_ = -1;
  std::string display_;
  std::string previous_display_;
  bool had_previous_ = false;
};

// The charts of `--plot F.EXT` (EXT = png, svg or pdf): the file name and the chart. One per measured metric, as
// its registry entry names it (temporal/compare/comparison.h): F.EXT per-frame PSNR (RGB); F-psnr-y.EXT,
// F-ssim.EXT, F-flicker.EXT (only when there are two frames or more), F-flip.EXT with --flip; F-speed.EXT: the
// mean of the report's speed metric (PSNR by default, `--speed-metric`) against the mean compute time of each
// test whose headers time the method itself (speed_points in temporal/compare/comparison.h), when there is one.
// Titles are the metric's, after `title` ("walkers: PSNR (rgb) per frame") when given; series are the sequences'
// names (--names). The speed chart also draws the Pareto front of its points as a line named "Pareto front" when
// it has two points or more.
// With regions (compare --regions motion): F-regions.EXT, each region's share of the valid pixels per frame, and
// F-psnr-static.EXT, F-psnr-moving.EXT, F-psnr-disoccluded.EXT, PSNR (RGB) per frame in the region.
std::vector<std::pair<std::string, Chart>> comparison_charts(const ComparisonReport& report,
                                                             const std::string& plot_path,
                                                             const std::string& title = {});

}  // namespace temporal
