// VTK charts written to PNG, SVG or PDF (temporal/plot/plot.h): vtkChartXY in an off-screen vtkContextView; PNG
// read back with vtkWindowToImageFilter and written with vtkPNGWriter, SVG through GL2PS (vtkGL2PSExporter), PDF
// as that SVG drawn by librsvg onto a cairo PDF surface. VTK's own PDF exporter (vtkPDFExporter, libharu) drew
// every data marker as a disc filling the plot area and referenced Helvetica without embedding it (issue 25);
// cairo draws the markers at their stated size and embeds the fonts it uses as subsets.
#include "temporal/plot/plot.h"

#include "temporal/io/atomic_file.h"

#include <vtkAxis.h>
#include <vtkBrush.h>
#include <vtkChartLegend.h>
#include <vtkChartXY.h>
#include <vtkContextScene.h>
#include <vtkContextView.h>
#include <vtkDoubleArray.h>
#include <vtkGL2PSExporter.h>
#include <vtkNew.h>
#include <vtkObject.h>
#include <vtkPNGWriter.h>
#include <vtkPen.h>
#include <vtkPlot.h>
#include <vtkPlotPoints.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkTable.h>
#include <vtkTextProperty.h>
#include <vtkWindowToImageFilter.h>

#include <cairo-pdf.h>
#include <cairo.h>
#include <librsvg/rsvg.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>

namespace temporal {
namespace {

// Okabe and Ito's colour-blind-safe palette (Color Universal Design, 2008), without its black (kept for text) and
// with its yellow last (faint on white), then a grey: in the order methods are given on the command line. Tableau
// 10's red and green, used before, are the pair that readers with a red-green deficiency cannot tell apart.
constexpr unsigned char kPalette[][3] = {{0, 114, 178},  {230, 159, 0},   {0, 158, 115}, {213, 94, 0},
                                         {204, 121, 167}, {86, 180, 233}, {240, 228, 66}, {127, 127, 127}};

// Writes the view as an SVG through GL2PS: text stays text. `svg_path` must end in ".svg" (GL2PS appends the
// extension to the prefix it is given).
void export_svg(vtkRenderWindow* window, const std::string& svg_path, const std::string& title) {
  const std::string prefix = svg_path.substr(0, svg_path.size() - 4);
  vtkNew<vtkGL2PSExporter> exporter;
  exporter->SetRenderWindow(window);
  exporter->SetFileFormatToSVG();
  exporter->SetFilePrefix(prefix.c_str());
  exporter->SetTitle(title.c_str());
  exporter->CompressOff();
  exporter->TextAsPathOff();  // text stays text: selectable, editable, searchable
  exporter->SilentOn();       // GL2PS would print notices to stderr; the library never prints
  exporter->Write();
}

// Draws the SVG at `svg_path` into a one-page PDF at `pdf_path`. One SVG pixel is 0.75 pt (CSS's 96 px per inch,
// as rsvg-convert and browsers print), so 14-pixel labels are 10.5 pt type on the page.
Status svg_to_pdf(const std::string& svg_path, const std::string& pdf_path, const std::string& title, int width,
                  int height) {
  GError* error = nullptr;
  RsvgHandle* svg = rsvg_handle_new_from_file(svg_path.c_str(), &error);
  auto fail = [&](const std::string& what) {
    std::string why = what;
    if (error) {
      why += std::string(": ") + error->message;
      g_error_free(error);
      error = nullptr;
    }
    return Error::output(pdf_path, why);
  };
  if (!svg) return fail("cannot read back the chart's SVG to draw the PDF");
  constexpr double kPointsPerPixel = 0.75;
  cairo_surface_t* surface = cairo_pdf_surface_create(pdf_path.c_str(), width * kPointsPerPixel,
                                                      height * kPointsPerPixel);
  cairo_pdf_surface_set_metadata(surface, CAIRO_PDF_METADATA_TITLE, title.c_str());
  cairo_pdf_surface_set_metadata(surface, CAIRO_PDF_METADATA_CREATOR, "temporal plot (VTK, librsvg, cairo)");
  cairo_t* cr = cairo_create(surface);
  cairo_scale(cr, kPointsPerPixel, kPointsPerPixel);
  const RsvgRectangle viewport{0.0, 0.0, double(width), double(height)};
  const gboolean drawn = rsvg_handle_render_document(svg, cr, &viewport, &error);
  cairo_destroy(cr);
  cairo_surface_finish(surface);
  const cairo_status_t status = cairo_surface_status(surface);
  cairo_surface_destroy(surface);
  g_object_unref(svg);
  if (!drawn) return fail("cannot draw the chart into the PDF");
  if (status != CAIRO_STATUS_SUCCESS)
    return Error::output(pdf_path, std::string("cannot write the PDF (") + cairo_status_to_string(status) +
                                       "): check that the folder is writable");
  return Status::ok();
}

}  // namespace

Expected<ChartFormat> chart_format(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".png") return ChartFormat::Png;
  if (ext == ".svg") return ChartFormat::Svg;
  if (ext == ".pdf") return ChartFormat::Pdf;
  return Error::usage("--plot '" + path + "': charts are written as .png, .svg or .pdf; " +
                      (ext.empty() ? std::string("add one of these extensions") : "'" + ext + "' is none of them"));
}

AxisRange chart_y_range(const Chart& chart) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const auto& series : chart.series)
    for (std::size_t i = 0; i < std::min(series.x.size(), series.y.size()); ++i)
      if (std::isfinite(series.y[i])) {
        lo = std::min(lo, series.y[i]);
        hi = std::max(hi, series.y[i]);
      }
  if (!(lo <= hi)) {  // nothing finite to show
    lo = chart.y_lowest.value_or(0.0);
    hi = chart.y_highest.value_or(lo + 1.0);
  }
  if (chart.y_min) lo = *chart.y_min;
  if (chart.y_max) hi = *chart.y_max;
  const double span = hi > lo ? hi - lo : std::max(1e-3, 0.1 * std::fabs(hi));
  if (!chart.y_min) lo -= 0.05 * span;
  if (!chart.y_max) hi += 0.05 * span;
  if (chart.y_lowest && !chart.y_min) lo = std::max(lo, *chart.y_lowest);
  if (chart.y_highest && !chart.y_max) hi = std::min(hi, *chart.y_highest);
  if (!(hi > lo)) hi = lo + span;  // a flat series at a bound (SSIM exactly 1 everywhere)
  return {lo, hi};
}

namespace {

// The x extent of the finite points of a chart (any = false when it has none).
struct XExtent {
  double xmin = std::numeric_limits<double>::infinity(), xmax = -std::numeric_limits<double>::infinity();
  bool any = false;
};

// Adds each series of `chart` to `xy` as a plot in its palette colour: curves, markers, the Pareto front (grey, thin)
// and error bars (no legend entry); returns the x extent of the finite points.
XExtent add_series(const Chart& chart, vtkChartXY& xy) {
  XExtent e;
  double& xmin = e.xmin;
  double& xmax = e.xmax;
  bool& any = e.any;
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
        xmin = std::min(xmin, series.x[i]);
        xmax = std::max(xmax, series.x[i]);
      }
    }
    table->AddColumn(xs);
    table->AddColumn(ys);
    const bool as_line = chart.style == ChartStyle::Lines || series.line || series.error_bar;
    vtkPlot* plot = xy.AddPlot(as_line ? vtkChart::LINE : vtkChart::POINTS);
    plot->SetInputData(table, 0, 1);
    plot->SetLabel(ys->GetName());
    const std::size_t entry = series.color >= 0 ? std::size_t(series.color) : s;
    const auto* c = kPalette[entry % (sizeof kPalette / sizeof kPalette[0])];
    if (series.line && chart.style == ChartStyle::Points) {
      plot->SetColor(110, 110, 110, 255);  // the front: grey, thin, behind the markers' colours
      plot->SetWidth(1.5f);
      if (auto* points = vtkPlotPoints::SafeDownCast(plot)) points->SetMarkerStyle(vtkPlotPoints::NONE);
      continue;
    }
    if (series.error_bar && chart.style == ChartStyle::Points) {
      plot->SetColor(c[0], c[1], c[2], 255);
      plot->SetWidth(1.5f);
      plot->SetLegendVisibility(false);
      if (auto* points = vtkPlotPoints::SafeDownCast(plot)) points->SetMarkerStyle(vtkPlotPoints::NONE);
      continue;
    }
    plot->SetColor(c[0], c[1], c[2], 255);
    plot->SetWidth(chart.style == ChartStyle::Lines ? 2.0f : 1.0f);
    if (auto* points = vtkPlotPoints::SafeDownCast(plot)) {
      const bool few = n <= 60;
      points->SetMarkerStyle(chart.style == ChartStyle::Points ? vtkPlotPoints::CIRCLE
                                                               : (few ? vtkPlotPoints::CIRCLE : vtkPlotPoints::NONE));
      points->SetMarkerSize(chart.style == ChartStyle::Points ? 14.0f : 6.0f);
    }
  }

  return e;
}

// Ranges with a margin, so single points and flat curves (identical frames) stay visible.
void set_axis_ranges(const Chart& chart, vtkChartXY& xy, const XExtent& e) {
  const double xmin = e.xmin, xmax = e.xmax;
  auto* left = xy.GetAxis(vtkAxis::LEFT);
  auto* bottom = xy.GetAxis(vtkAxis::BOTTOM);
  if (e.any) {
    const AxisRange y = chart_y_range(chart);
    left->SetBehavior(vtkAxis::FIXED);
    left->SetRange(y.low, y.high);
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

}

}  // namespace

Status write_chart(const Chart& chart, const std::string& path) {
  auto format = chart_format(path);
  if (!format) return format.error();
  if (chart.series.empty()) return Error::usage("chart '" + chart.title + "' has no series to draw");
  if (chart.width < 64 || chart.height < 64) return Error::usage("chart size must be at least 64x64 pixels");

  // VTK prints its errors and warnings to stderr itself (e.g. "Attempted to paint a line with <2 points", from a
  // legend entry, on every chart): the library never prints, and a chart that fails shows as a missing file below.
  vtkObject::GlobalWarningDisplayOff();
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
  xy->GetLegend()->SetInline(false);  // to the right of the plot area: it never hides a curve
  xy->GetLegend()->SetHorizontalAlignment(vtkChartLegend::RIGHT);
  xy->GetLegend()->SetVerticalAlignment(vtkChartLegend::TOP);
  xy->GetAxis(vtkAxis::BOTTOM)->SetTitle(chart.x_label);
  xy->GetAxis(vtkAxis::LEFT)->SetTitle(chart.y_label);
  for (int a : {vtkAxis::BOTTOM, vtkAxis::LEFT}) {
    xy->GetAxis(a)->GetTitleProperties()->SetFontSize(14);
    xy->GetAxis(a)->GetLabelProperties()->SetFontSize(12);
  }

  const XExtent extent = add_series(chart, *xy);
  set_axis_ranges(chart, *xy, extent);

  view->GetRenderWindow()->Render();
  TemporaryFile tmp(path);  // removed on failure and on SIGINT; the extension is kept
  if (*format == ChartFormat::Png) {
    vtkNew<vtkWindowToImageFilter> grab;
    grab->SetInput(view->GetRenderWindow());
    grab->SetInputBufferTypeToRGB();
    grab->ReadFrontBufferOff();
    grab->Update();
    vtkNew<vtkPNGWriter> writer;
    writer->SetFileName(tmp.path().c_str());
    writer->SetInputConnection(grab->GetOutputPort());
    writer->Write();
    if (writer->GetErrorCode() != 0) return Error::output(path, "cannot write the PNG: check that the folder is writable");
  } else if (*format == ChartFormat::Svg) {
    export_svg(view->GetRenderWindow(), tmp.path(), chart.title);
  } else {
    TemporaryFile svg(path + ".svg");  // the drawing the PDF is made from; removed when done
    export_svg(view->GetRenderWindow(), svg.path(), chart.title);
    if (Status s = svg_to_pdf(svg.path(), tmp.path(), chart.title, chart.width, chart.height); !s) return s;
  }
  std::error_code ec;
  // The non-throwing forms: a file that cannot be examined is this output's error (exit 4), not an exception.
  if (!std::filesystem::exists(tmp.path(), ec) || ec || std::filesystem::file_size(tmp.path(), ec) == 0 || ec)
    return Error::output(path, "the chart could not be written: check that the folder exists and is writable");
  return tmp.commit();
}

}  // namespace temporal
