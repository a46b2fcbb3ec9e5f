// PNG charts (VTK), behind a header that does not include VTK: only `compare` links the `temporal::plot`
// target, which keeps libGL (pulled in by VTK) out of every other program (docs/building.md, OSMesa trap).
//
// Debian's VTK renders through X11 only. VirtualDisplay provides a display when none is usable: it starts
// `Xvfb -displayfd N -nolisten tcp` on a free display number and points $DISPLAY at it for this process.
#pragma once

#include "temporal/core/error.h"
#include "temporal/metrics/comparison.h"

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
};

enum class ChartStyle {
  Lines,   // polyline through the points with small markers (per-frame metric curves)
  Points,  // markers only (speed against error: one point per method)
};

// Everything a chart shows. Axis ranges are automatic unless given.
struct Chart {
  std::string title;
  std::string x_label;
  std::string y_label;
  std::vector<ChartSeries> series;
  ChartStyle style = ChartStyle::Lines;
  int width = 1280;  // PNG size in pixels
  int height = 720;
  std::optional<double> y_min;
  std::optional<double> y_max;
};

// Renders `chart` off screen and writes it as an 8-bit RGB PNG (atomically: temporary file, then rename).
// Needs an X display (see VirtualDisplay). Errors: Output when the PNG cannot be written, Usage for an empty
// chart.
Status write_chart_png(const Chart& chart, const std::string& path);

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

// The charts of `--plot F.png`: the file name and the chart. One per measured metric, as its registry entry
// names it (temporal/metrics/comparison.h): F.png per-frame PSNR (RGB); F-psnr-y.png, F-ssim.png,
// F-flicker.png (only when there are two frames or more), F-flip.png with --flip; F-speed.png: mean PSNR against
// mean compute time, when any test header has timings.
std::vector<std::pair<std::string, Chart>> comparison_charts(const ComparisonReport& report,
                                                             const std::string& plot_path);

}  // namespace temporal
