// The HTML report page (temporal/pictures/html.h).
#include "temporal/pictures/html.h"

#include "temporal/io/atomic_file.h"
#include "temporal/metrics/statistics.h"

#include <cmath>
#include <cstdio>
#include <sstream>

namespace temporal {
namespace {

constexpr const char* kStyle = R"(
body { font-family: "DejaVu Sans", Helvetica, Arial, sans-serif; margin: 1.5em; color: #222; background: #fff; }
h1 { font-size: 1.5em; margin-bottom: 0.2em; }
h2 { font-size: 1.2em; margin-top: 1.6em; border-bottom: 1px solid #ccc; }
p.meta, p.note { color: #555; font-size: 0.9em; }
code { font-size: 0.9em; }
table { border-collapse: collapse; margin: 0.6em 0; font-size: 0.9em; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: right; white-space: nowrap; }
th { background: #f2f2f2; }
td.name, th.name { text-align: left; }
td.best { font-weight: bold; }
span.ci { color: #666; font-size: 0.85em; }
td.decided { color: #0072b2; font-weight: bold; } td.winner { font-weight: bold; } td.tie { color: #666; }
div.share { display: flex; width: 30em; height: 1.2em; border: 1px solid #ccc; font-size: 0.8em; }
div.share span { display: block; overflow: hidden; text-align: center; color: #fff; }
span.static { background: #0072b2; } span.moving { background: #e69f00; } span.disoccluded { background: #cc79a7; }  /* Okabe-Ito */
figure { display: inline-block; margin: 0.5em 1em 1em 0; vertical-align: top; max-width: 100%; }
figcaption { font-size: 0.85em; color: #444; max-width: 60em; }
img { border: 1px solid #ddd; max-width: 100%; height: auto; }
figure.chart { width: 640px; }
img.chart { width: 100%; }
div.mapped { position: relative; display: inline-block; max-width: 100%; }
div.mapped img { width: 100%; height: auto; display: block; }
div.mapped a { position: absolute; display: block; }
div.mapped a:hover { outline: 2px solid #1f77b4; }
video { max-width: 100%; height: auto; background: #222; }
#load-status { display: none; background: #fde2e2; padding: 0.5em; }
)";

// Sets data-images-complete="N/M" on <body> once everything loaded, and shows a warning when a picture failed.
constexpr const char* kScript = R"(
window.addEventListener('load', function () {
  var images = Array.prototype.slice.call(document.images);
  var complete = images.filter(function (i) { return i.complete && i.naturalWidth > 0; });
  document.body.setAttribute('data-images-complete', complete.length + '/' + images.length);
  var video = document.querySelector('video');
  if (video) document.body.setAttribute('data-video-ready-state', String(video.readyState));
  if (complete.length < images.length) {
    var s = document.getElementById('load-status');
    s.textContent = (images.length - complete.length) + ' of ' + images.length +
      ' pictures did not load: was the report folder moved without its files?';
    s.style.display = 'block';
  }
});
)";

std::string cell_value(const MeanInterval& m, int digits) {
  if (m.count == 0) return "–";
  std::string s = format_number(m.mean, digits);
  if (std::isfinite(m.ci.low) || std::isfinite(m.ci.high))
    s += "<br><span class=\"ci\">[" + format_number(m.ci.low, digits) + ", " + format_number(m.ci.high, digits) + "]</span>";
  return s;
}

void metric_table(std::ostringstream& out, const ComparisonReport& r) {
  out << "<table class=\"metrics\">\n<tr><th class=\"name\">sequence</th><th>frames</th>";
  std::vector<const MetricDefinition*> defs;
  for (const auto& name : r.metrics)
    if (const MetricDefinition* d = find_metric(name)) defs.push_back(d);
  for (const auto* d : defs)
    out << "<th>" << html_escape(d->name) << (d->unit.empty() ? "" : " (" + html_escape(d->unit) + ")")
        << (d->higher_is_better ? " ↑" : " ↓") << "</th>";
  for (const auto* d : defs)
    if (d->pooled) out << "<th>" << html_escape(d->name) << "_pooled (" << html_escape(d->unit) << ") ↑</th>";
  out << "<th>compute ms</th></tr>\n";
  // The best mean of each metric in bold.
  std::vector<double> best(defs.size(), std::nan(""));
  for (std::size_t k = 0; k < defs.size(); ++k)
    for (const auto& s : r.sequences) {
      const double m = summarize(s, defs[k]->name).mean;
      if (std::isnan(m)) continue;
      if (std::isnan(best[k]) || (defs[k]->higher_is_better ? m > best[k] : m < best[k])) best[k] = m;
    }
  for (const auto& s : r.sequences) {
    out << "<tr><td class=\"name\">" << html_escape(s.name) << "</td><td>" << s.frames.size() << "</td>";
    for (std::size_t k = 0; k < defs.size(); ++k) {
      const auto series = metric_series(s, defs[k]->name);
      const MeanInterval m = bootstrap_mean(series, r.bootstrap);
      const bool is_best = m.count && r.sequences.size() > 1 && m.mean == best[k];
      out << "<td" << (is_best ? " class=\"best\"" : "") << ">" << cell_value(m, 4) << "</td>";
    }
    for (const auto* d : defs)
      if (d->pooled) out << "<td>" << cell_value(pooled_summary(s, d->name, kAllRegions, r.bootstrap), 4) << "</td>";
    const auto ms = mean_compute_ms(s);
    out << "<td>" << (ms ? format_number(*ms, 3) : std::string("–"))
        << (ms && s.compute_kind != ComputeKind::Method ? " (" + std::string(compute_kind_name(s.compute_kind)) + ")" : "")
        << "</td></tr>\n";
  }
  out << "</table>\n";
}

// With --regions: a stacked bar of the region shares and a table of every metric per region (mean over frames
// with its interval, pooled PSNR with its interval) for each sequence.
void region_section(std::ostringstream& out, const ComparisonReport& r) {
  if (!r.regions || r.sequences.empty()) return;
  char tolerance[32];
  std::snprintf(tolerance, sizeof tolerance, "%g", r.region_options.static_tolerance);
  out << "<h2 id=\"regions\">Regions</h2>\n<p class=\"note\">From the G-buffer (docs/compare.md, Regions): "
         "<b>static</b> = zero motion, history found and the reference's luminance unchanged (within "
      << tolerance << ") for " << r.region_options.static_frames
      << " frames; <b>disoccluded</b> = no history (the reprojection's off-screen or depth/id test fails, or no previous "
         "frame); <b>moving</b> = the rest. Each value is the mean over the frames where the region has pixels, with its "
         "95 % interval; <code>_pooled</code> is the PSNR of the region's squared error pooled over all its pixels of "
         "all frames. Flicker has no value where disoccluded (no history).</p>\n";
  std::vector<const MetricDefinition*> defs;
  for (const auto& name : r.metrics)
    if (const MetricDefinition* d = find_metric(name)) defs.push_back(d);
  for (const auto& s : r.sequences) {
    out << "<p class=\"note\">" << html_escape(s.name) << ": share of the valid pixels</p>\n<div class=\"share\">";
    for (int g = 0; g < kRegionCount; ++g) {
      const double share = region_share(s, g);
      const double pct = std::isfinite(share) ? 100.0 * share : 0.0;
      char width[32];
      std::snprintf(width, sizeof width, "%.3f%%", pct);
      out << "<span class=\"" << region_name(g) << "\" style=\"width:" << width << "\" title=\"" << region_name(g)
          << " " << format_number(pct, 3) << " %\">" << (pct >= 12.0 ? region_name(g) : "") << "</span>";
    }
    out << "</div>\n";
  }
  out << "<table class=\"regions\">\n<tr><th class=\"name\">sequence</th><th class=\"name\">region</th><th>share</th>";
  for (const auto* d : defs)
    out << "<th>" << html_escape(d->name) << (d->higher_is_better ? " ↑" : " ↓") << "</th>";
  for (const auto* d : defs)
    if (d->pooled) out << "<th>" << html_escape(d->name) << "_pooled ↑</th>";
  out << "</tr>\n";
  for (const auto& s : r.sequences)
    for (int g = 0; g < kRegionCount; ++g) {
      out << "<tr><td class=\"name\">" << html_escape(s.name) << "</td><td class=\"name\">" << region_name(g)
          << "</td><td>" << format_number(100.0 * region_share(s, g), 3) << " %</td>";
      for (const auto* d : defs)
        out << "<td>" << cell_value(bootstrap_mean(region_series(s, d->name, g), r.bootstrap), 4) << "</td>";
      for (const auto* d : defs)
        if (d->pooled) out << "<td>" << cell_value(pooled_summary(s, d->name, g, r.bootstrap), 4) << "</td>";
      out << "</tr>\n";
    }
  out << "</table>\n";
}

void paired_table(std::ostringstream& out, const ComparisonReport& r) {
  if (r.sequences.size() < 2) return;
  out << "<h2 id=\"paired\">Paired differences</h2>\n<p class=\"note\">Mean over frames of a − b with its 95 % "
         "moving-block bootstrap interval (the JSON's <code>paired</code>). “a better” or “b better” when the "
         "interval excludes 0; “no difference” otherwise. <code>_pooled</code> rows: pooled(a) − pooled(b), the "
         "same frames resampled for both.</p>\n";
  out << "<table class=\"paired\">\n<tr><th class=\"name\">a</th><th class=\"name\">b</th><th class=\"name\">metric</th>"
      << (r.regions ? "<th class=\"name\">region</th>" : "") << "<th>a − b [95 %]</th><th class=\"name\">verdict</th></tr>\n";
  const int last_region = r.regions ? kRegionCount - 1 : kAllRegions;
  // The verdict names the better method in bold blue (Okabe-Ito's blue: colour-blind safe) and bolds its name in
  // the row; colouring "a better" green and "b better" red would colour by the row's order, not by which is
  // better, and red/green is what colour-blind readers cannot tell apart (issue 25).
  auto row = [&](std::size_t a, std::size_t b, const std::string& name, bool higher, int region, const MeanInterval& m) {
    std::string verdict = "no difference", cls = "tie", a_cls, b_cls;
    const bool above = m.ci.low > 0.0, below = m.ci.high < 0.0;
    if (above || below) {
      const bool a_better = higher ? above : below;
      verdict = (a_better ? r.sequences[a].name : r.sequences[b].name) + " better";
      cls = "decided";
      (a_better ? a_cls : b_cls) = " winner";
    }
    out << "<tr><td class=\"name" << a_cls << "\">" << html_escape(r.sequences[a].name) << "</td><td class=\"name"
        << b_cls << "\">" << html_escape(r.sequences[b].name) << "</td><td class=\"name\">" << html_escape(name) << "</td>"
        << (r.regions ? "<td class=\"name\">" + std::string(region_name(region)) + "</td>" : std::string()) << "<td>"
        << cell_value(m, 3) << "</td><td class=\"name " << cls << "\">" << html_escape(verdict) << "</td></tr>\n";
  };
  for (std::size_t a = 0; a < r.sequences.size(); ++a)
    for (std::size_t b = a + 1; b < r.sequences.size(); ++b)
      for (int g = kAllRegions; g <= last_region; ++g)
        for (const auto& name : r.metrics) {
          const MetricDefinition* d = find_metric(name);
          if (!d) continue;
          const auto sa = region_series(r.sequences[a], name, g), sb = region_series(r.sequences[b], name, g);
          const MeanInterval m = bootstrap_paired_difference(sa, sb, r.bootstrap);
          if (m.count == 0) continue;
          row(a, b, name, d->higher_is_better, g, m);
          if (d->pooled) {
            const MeanInterval p = pooled_difference(r.sequences[a], r.sequences[b], name, g, r.bootstrap);
            if (p.count) row(a, b, name + "_pooled", true, g, p);
          }
        }
  out << "</table>\n";
}

// A percentage of `part` in `whole`, for CSS.
std::string percent(int part, int whole) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4f%%", whole > 0 ? 100.0 * double(part) / double(whole) : 0.0);
  return text;
}

// A picture linked to its data: one link around it, or (areas) a link over each of its parts, placed in
// percentages of the picture so that they stay on their parts when the page shrinks the picture.
void image(std::ostringstream& out, const ReportImage& im) {
  out << "<figure class=\"" << html_escape(im.kind) << "\">";
  const std::string img = "<img class=\"" + html_escape(im.kind) + "\" src=\"" + html_escape(im.file) + "\" alt=\"" +
                          html_escape(im.alt.empty() ? im.caption : im.alt) + "\"" +
                          (im.width > 0 ? " width=\"" + std::to_string(im.width) + "\"" : "") +
                          (im.height > 0 ? " height=\"" + std::to_string(im.height) + "\"" : "") + ">";
  if (im.areas.empty() || im.width <= 0 || im.height <= 0) {
    out << "<a href=\"" << html_escape(im.link.empty() ? im.file : im.link) << "\">" << img << "</a>";
  } else {
    out << "<div class=\"mapped\" style=\"width: " << im.width << "px\">" << img;
    for (const auto& a : im.areas) {
      if (a.link.empty()) continue;
      out << "<a href=\"" << html_escape(a.link) << "\" title=\"" << html_escape(a.tooltip) << "\" style=\"left: "
          << percent(a.rect.x, im.width) << "; top: " << percent(a.rect.y, im.height) << "; width: "
          << percent(a.rect.width, im.width) << "; height: " << percent(a.rect.height, im.height) << "\"></a>";
    }
    out << "</div>";
  }
  if (!im.caption.empty()) {
    out << "<figcaption>" << html_escape(im.caption);
    if (!im.areas.empty()) out << " Each picture in it links to its EXR.";
    out << "</figcaption>";
  }
  out << "</figure>\n";
}

}  // namespace

std::string html_escape(std::string_view text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string format_number(double value, int digits) {
  if (std::isnan(value)) return "–";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char text[64];
  const double a = std::fabs(value);
  if (a != 0.0 && (a < 1e-4 || a >= 1e7)) {
    std::snprintf(text, sizeof text, "%.*e", digits - 1, value);
  } else {
    // `digits` significant digits, fixed notation: 31.42, 0.9123, 0.04125.
    const int magnitude = a == 0.0 ? 0 : int(std::floor(std::log10(a)));
    std::snprintf(text, sizeof text, "%.*f", std::max(0, digits - 1 - magnitude), value);
  }
  return text;
}

std::string html_report(const HtmlReport& rep) {
  std::ostringstream out;
  out << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>" << html_escape(rep.title)
      << "</title>\n<style>" << kStyle << "</style>\n<script>" << kScript << "</script>\n</head>\n<body>\n";
  out << "<div id=\"load-status\"></div>\n<h1>" << html_escape(rep.title) << "</h1>\n";
  if (const ComparisonReport* r = rep.comparison) {
    out << "<p class=\"meta\">Reference <code>" << html_escape(r->reference) << "</code> (layer "
        << html_escape(r->reference_layer) << "), " << r->width << "x" << r->height << ", frames "
        << (r->frames.empty() ? 0 : r->frames.front()) << "–" << (r->frames.empty() ? 0 : r->frames.back()) << " ("
        << r->frames.size() << (r->fps ? ", " + format_number(*r->fps, 4) + " frames/s" : std::string()) << ")"
        << (r->motion_compensated ? "; flicker motion-compensated with <code>" + html_escape(r->gbuffer) + "</code>"
                                  : std::string())
        << (r->flip != FlipMode::Off ? "; " + std::string(r->flip == FlipMode::Ldr ? "LDR" : "HDR") + "-FLIP at " +
                                           format_number(r->pixels_per_degree, 4) + " pixels per degree"
                                     : std::string())
        << ".</p>\n";
    out << "<p class=\"meta\">Written by " << html_escape(rep.generator) << ": <code>" << html_escape(rep.command_line)
        << "</code></p>\n";
    out << "<h2 id=\"metrics\">Metrics</h2>\n<p class=\"note\">Mean over frames with its 95 % moving-block bootstrap "
           "interval in brackets (the JSON's <code>ci95</code>); ↑ higher is better, ↓ lower; the best mean in bold. "
           "Compute ms: mean <code>temporal:computeMs</code> of the test's headers (render or simulation time is "
           "marked: it is not the method's cost).</p>\n";
    metric_table(out, *r);
    region_section(out, *r);
    if (!rep.failures.empty()) {
      out << "<p class=\"note\"><b>Thresholds failed:</b></p>\n<ul>\n";
      for (const auto& f : rep.failures) out << "<li>" << html_escape(f.message()) << "</li>\n";
      out << "</ul>\n";
    }
    for (const auto& note : rep.notes) out << "<p class=\"note\">" << html_escape(note) << "</p>\n";
  }
  if (!rep.files.empty()) {
    out << "<p class=\"note\">Data:";
    for (const auto& [label, href] : rep.files)
      out << " <a href=\"" << html_escape(href) << "\">" << html_escape(label) << "</a>";
    out << "</p>\n";
  }
  bool video_done = rep.video.empty();
  for (const auto& section : rep.sections) {
    out << "<h2 id=\"" << html_escape(section.id) << "\">" << html_escape(section.heading) << "</h2>\n";
    if (!section.text.empty()) out << "<p class=\"note\">" << html_escape(section.text) << "</p>\n";
    for (const auto& im : section.images) image(out, im);
    if (!video_done && section.id == "sheet") {  // the video follows the contact sheet
      video_done = true;
      out << "<h2 id=\"video\">Side-by-side video</h2>\n<figure class=\"video\"><video controls loop muted playsinline "
             "preload=\"metadata\" src=\""
          << html_escape(rep.video) << "\"" << (rep.video_poster.empty() ? "" : " poster=\"" + html_escape(rep.video_poster) + "\"")
          << (rep.video_width > 0 ? " width=\"" + std::to_string(rep.video_width) + "\" height=\"" +
                                        std::to_string(rep.video_height) + "\""
                                  : "")
          << "></video><figcaption>"
          << html_escape(rep.video_caption) << " <a href=\"" << html_escape(rep.video) << "\">MP4</a></figcaption></figure>\n";
    }
  }
  if (!video_done)
    out << "<h2 id=\"video\">Side-by-side video</h2>\n<figure class=\"video\"><video controls loop muted src=\""
        << html_escape(rep.video) << "\"></video><figcaption>" << html_escape(rep.video_caption) << "</figcaption></figure>\n";
  if (rep.comparison) paired_table(out, *rep.comparison);  // long with many methods: last
  out << "</body>\n</html>\n";
  return out.str();
}

Status write_html_report(const HtmlReport& report, const std::string& path) {
  return write_text_atomic(path, html_report(report));
}

}  // namespace temporal
