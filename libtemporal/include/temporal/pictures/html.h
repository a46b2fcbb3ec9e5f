// The HTML report of one comparison (`compare --report DIR`): one offline page, `index.html`, with the metric
// tables (each mean with its 95 % interval, the paired differences with theirs, as the JSON holds them:
// temporal/metrics/statistics.h), the charts, the contact sheet, FLIP and error maps, temporal profiles and the
// side-by-side video, then the paired differences. Every picture links to the EXR it shows (a sheet: each part to
// its own). Nothing is fetched from a network: styles and the small script are inline, every file is relative to
// the page.
//
// The script only reports: once the page has loaded it counts the pictures that did not load and says so at the
// top of the page, and sets `data-images-complete="N/M"` on <body> (a headless browser's DOM dump shows it).
#pragma once

#include "temporal/core/error.h"
#include "temporal/compare/comparison.h"
#include "temporal/pictures/sheet.h"

#include <string>
#include <utility>
#include <vector>

namespace temporal {

struct ReportImage {
  std::string file;     // the picture, relative to the page
  std::string link;     // what it links to (its EXR), relative to the page; empty: the picture itself
  std::string caption;  // under the picture
  std::string alt;      // short description
  std::string kind;     // CSS class: "chart", "sheet", "flip", "error", "profile", "gbuffer"
  int width = 0, height = 0;      // the picture's size in pixels
  std::vector<SheetArea> areas;   // parts with their own links (a contact sheet's frames, maps, crops): each
                                  // becomes a link over its part, placed in percentages of the picture
};

struct ReportSection {
  std::string id;       // anchor
  std::string heading;
  std::string text;     // a paragraph under the heading (plain text)
  std::vector<ReportImage> images;
};

struct HtmlReport {
  std::string title;
  std::string generator;     // "compare 0.1.0"
  std::string command_line;
  const ComparisonReport* comparison = nullptr;
  std::vector<ThresholdFailure> failures;
  std::vector<std::string> notes;                            // shown under the tables
  std::vector<std::pair<std::string, std::string>> files;   // (label, relative href): metrics.csv, metrics.json
  std::vector<ReportSection> sections;                       // in page order, after the tables
  std::string video;          // relative path of the MP4; empty: none
  std::string video_poster;   // its first frame as a picture
  std::string video_caption;
  int video_width = 0, video_height = 0;
};

// The page's text.
std::string html_report(const HtmlReport& report);
// Writes it atomically to `path`.
Status write_html_report(const HtmlReport& report, const std::string& path);

// Text escaped for HTML content and attribute values.
std::string html_escape(std::string_view text);
// A number with `digits` significant digits; "inf", "-inf", "–" (no value) otherwise.
std::string format_number(double value, int digits = 4);

}  // namespace temporal
