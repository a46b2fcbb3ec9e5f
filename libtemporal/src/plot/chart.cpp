// VTK charts written to PNG (temporal/plot/plot.h): vtkChartXY in an off-screen vtkContextView, read back with
// vtkWindowToImageFilter and written with vtkPNGWriter.
#include "temporal/plot/plot.h"

#include <vtkAxis.h>
#include <vtkBrush.h>
#include <vtkChartLegend.h>
#include <vtkChartXY.h>
#include <vtkContextScene.h>
#include <vtkContextView.h>
#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkPen.h>
#include <vtkPlot.h>
#include <vtkPlotPoints.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkTable.h>
#include <vtkTextProperty.h>
#include <vtkWindowToImageFilter.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>

namespace temporal {
namespace {

// Tableau 10: distinguishable colours, in the order methods are given on the command line.
constexpr unsigned char kPalette[][3] = {{31, 119, 180}, {255, 127, 14}, {44, 160, 44},  {214, 39, 40},
                                         {148, 103, 189}, {140, 86, 75}, {227, 119, 194}, {127, 127, 127},
                                         {188, 189, 34}, {23, 190, 207}};

}  // namespace

Status write_chart_png(const Chart& chart, const std::string& path) {
  if (chart.series.empty()) return Error::usage("chart '" + chart.title + "' has no series to draw");
  if (chart.width < 64 || chart.height < 64) return Error::usage("chart size must be at least 64x64 pixels");

  vtkNew<vtkContextView> view;
  view->GetRenderer()->SetBackground(1.0, 1.0, 1.0);
  view->GetRenderWindow()->SetSize(chart.width, chart.height);
  view->GetRenderWindow()->SetOffScreenRendering(1);
  view->GetRenderWindow()->SetMultiSamples(0);

  vtkNew<vtkChartXY> xy;
  view->GetScene()->AddItem(xy);
  xy->SetTitle(chart.title);
  xy->GetTitleProperties()->SetFontSize(18);
  xy->SetShowLegend(true);
  xy->GetLegend()->GetLabelProperties()->SetFontSize(14);
  xy->GetAxis(vtkAxis::BOTTOM)->SetTitle(chart.x_label);
  xy->GetAxis(vtkAxis::LEFT)->SetTitle(chart.y_label);
  for (int a : {vtkAxis::BOTTOM, vtkAxis::LEFT}) {
    xy->GetAxis(a)->GetTitleProperties()->SetFontSize(14);
    xy->GetAxis(a)->GetLabelProperties()->SetFontSize(12);
  }

  double ymin = std::numeric_limits<double>::infinity(), ymax = -ymin;
  double xmin = ymin, xmax = -ymin;
  bool any = false;
  for (std::size_t s = 0; s < chart.series.size(); ++s) {
    const auto& series = chart.series[s];
    vtkNew<vtkTable> table;
    vtkNew<vtkDoubleArray> xs;
    xs->SetName("x");
    vtkNew<vtkDoubleArray> ys;
    ys->SetName(series.name.empty() ? ("series " + std::to_string(s + 1)).c_str() : series.name.c_str());
    const std::size_t n = std::min(series.x.size(), series.y.size());
    xs->SetNumberOfValues(vtkIdType(n));
    ys->SetNumberOfValues(vtkIdType(n));
    for (std::size_t i = 0; i < n; ++i) {
      const double y = std::isfinite(series.y[i]) ? series.y[i] : std::numeric_limits<double>::quiet_NaN();
      xs->SetValue(vtkIdType(i), series.x[i]);
      ys->SetValue(vtkIdType(i), y);
      if (std::isfinite(y)) {
        any = true;
        ymin = std::min(ymin, y);
        ymax = std::max(ymax, y);
        xmin = std::min(xmin, series.x[i]);
        xmax = std::max(xmax, series.x[i]);
      }
    }
    table->AddColumn(xs);
    table->AddColumn(ys);
    vtkPlot* plot = xy->AddPlot(chart.style == ChartStyle::Lines ? vtkChart::LINE : vtkChart::POINTS);
    plot->SetInputData(table, 0, 1);
    plot->SetLabel(ys->GetName());
    const auto* c = kPalette[s % (sizeof kPalette / sizeof kPalette[0])];
    plot->SetColor(c[0], c[1], c[2], 255);
    plot->SetWidth(chart.style == ChartStyle::Lines ? 2.0f : 1.0f);
    if (auto* points = vtkPlotPoints::SafeDownCast(plot)) {
      const bool few = n <= 60;
      points->SetMarkerStyle(chart.style == ChartStyle::Points ? vtkPlotPoints::CIRCLE
                                                               : (few ? vtkPlotPoints::CIRCLE : vtkPlotPoints::NONE));
      points->SetMarkerSize(chart.style == ChartStyle::Points ? 14.0f : 6.0f);
    }
  }

  // Ranges with a margin, so single points and flat curves (identical frames) stay visible.
  auto* left = xy->GetAxis(vtkAxis::LEFT);
  auto* bottom = xy->GetAxis(vtkAxis::BOTTOM);
  if (any) {
    double lo = chart.y_min.value_or(ymin), hi = chart.y_max.value_or(ymax);
    const double span = hi > lo ? hi - lo : std::max(1e-3, 0.1 * std::fabs(hi));
    // Headroom at the top for the legend (top right, inside the plot), so it does not hide the highest points.
    const double legend = 0.06 * double(chart.series.size()) + 0.04;
    if (!chart.y_min) lo -= 0.05 * span;
    if (!chart.y_max) hi += (0.05 + legend) * span;
    left->SetBehavior(vtkAxis::FIXED);
    left->SetRange(lo, hi);
    const double xfrac = chart.style == ChartStyle::Points ? 0.1 : 0.02;  // markers need room at the edges
    const double xpad = xmax > xmin ? xfrac * (xmax - xmin) : std::max(0.5, 0.1 * std::fabs(xmax));
    bottom->SetBehavior(vtkAxis::FIXED);
    bottom->SetRange(xmin - xpad, xmax + xpad);
    // Whole-number x (frame numbers): ticks on whole numbers only, at a 1-2-5 step giving at most ~12 ticks.
    bool whole = true;
    for (const auto& series : chart.series)
      for (double x : series.x) whole = whole && std::floor(x) == x;
    if (whole && chart.style == ChartStyle::Lines) {
      const double xspan = std::max(1.0, xmax - xmin);
      double step = 1.0;
      for (double base = 1.0; xspan / step > 12.0; base *= 10.0)
        for (double m : {1.0, 2.0, 5.0})
          if (xspan / step > 12.0) step = m * base;
      vtkNew<vtkDoubleArray> ticks;
      for (double t = std::ceil(xmin / step) * step; t <= xmax; t += step) ticks->InsertNextValue(t);
      bottom->SetCustomTickPositions(ticks);
      bottom->SetNotation(vtkAxis::FIXED_NOTATION);
      bottom->SetPrecision(0);
    }
  }

  view->GetRenderWindow()->Render();
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(view->GetRenderWindow());
  grab->SetInputBufferTypeToRGB();
  grab->ReadFrontBufferOff();
  grab->Update();

  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path out(path);
  if (out.has_parent_path()) fs::create_directories(out.parent_path(), ec);
  const std::string tmp = path + ".tmp.png";
  vtkNew<vtkPNGWriter> writer;
  writer->SetFileName(tmp.c_str());
  writer->SetInputConnection(grab->GetOutputPort());
  writer->Write();
  if (writer->GetErrorCode() != 0 || !fs::exists(tmp) || fs::file_size(tmp, ec) == 0) {
    fs::remove(tmp, ec);
    return Error::output(path, "cannot write the PNG: check that the folder exists and is writable");
  }
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    return Error::output(path, "cannot move the PNG into place: " + ec.message());
  }
  return {};
}

}  // namespace temporal
