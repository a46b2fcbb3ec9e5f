// One compare run and its outputs (temporal/report/compare_run.h).
#include "temporal/report/compare_run.h"

#include "temporal/io/runner.h"
#include "temporal/pictures/html.h"
#include "temporal/plot/plot.h"

#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <optional>

namespace temporal {
namespace {

namespace fs = std::filesystem;

// The charts of a run: --plot's files, and the report's PNGs under DIR/plots. One virtual display for both.
void write_charts(const ComparisonReport& report, const CompareOutputs& o, const ProtectedInputs& inputs,
                  const ComparisonHooks& hooks, CompareRun& run, std::vector<ReportImage>* report_charts) {
  std::vector<std::pair<std::string, Chart>> charts;
  if (!o.plot.empty()) charts = comparison_charts(report, o.plot, o.title);
  std::size_t report_first = charts.size();
  if (report_charts) {
    auto r = comparison_charts(report, (fs::path(o.pictures.report_dir) / "plots" / "metrics.png").string(), o.title);
    charts.insert(charts.end(), std::make_move_iterator(r.begin()), std::make_move_iterator(r.end()));
  }
  if (charts.empty()) return;
  auto display = VirtualDisplay::ensure();
  if (!display) {
    run.output_errors.push_back(Error::output(o.plot.empty() ? o.pictures.report_dir : o.plot, display.error().message));
    return;
  }
  if (display->started() && hooks.log)
    hooks.log("DISPLAY is not usable: started Xvfb on " + display->display() + " for the plots");
  for (std::size_t i = 0; i < charts.size(); ++i) {
    const auto& [path, chart] = charts[i];
    if (auto st = inputs.check(path, i < report_first ? "--plot" : "--report"); !st) {
      run.output_errors.push_back(st.error());
      continue;
    }
    if (auto st = write_chart(chart, path); !st) {
      run.output_errors.push_back(st.error());
      continue;
    }
    if (hooks.log) hooks.log("wrote " + path);
    if (i >= report_first && report_charts)
      report_charts->push_back({"plots/" + fs::path(path).filename().string(), {}, chart.title, chart.title, "chart",
                                chart.width, chart.height, {}});
  }
}

// Why a sequence is left off the speed chart (ComputeKind).
std::vector<std::string> speed_notes(const ComparisonReport& report) {
  std::vector<std::string> notes;
  for (const auto& s : report.sequences) {
    if (s.compute_kind == ComputeKind::Method || !mean_compute_ms(s)) continue;
    notes.push_back(s.name + ": left off the speed chart, its compute time is " +
                    (s.compute_kind == ComputeKind::Render ? std::string("the render's (written by ") + s.tool + ")"
                                                           : std::string("the perception simulation's (morph-120hz --perceive)")) +
                    ", not a method's.");
  }
  return notes;
}

// What a report owns in its folder (docs/compare.md, Report): these files and folders, nothing else.
constexpr const char* kReportFiles[] = {"index.html", "metrics.csv", "metrics.json", "video.mp4"};
constexpr const char* kReportFolders[] = {"pictures", "plots", "maps", "profiles"};

// A report written into a folder that holds an earlier one left the earlier run's pictures beside the new ones
// (another method's maps, charts of a metric not measured now: issue 25). An earlier report (its index.html says
// "Written by compare") is removed first - only what a report owns, and never a file this run reads; report
// files in a folder without that page are someone else's: refused.
Status clear_earlier_report(const std::string& dir, const ProtectedInputs& inputs, const ComparisonHooks& hooks) {
  std::error_code ec;
  const fs::file_status st = fs::status(dir, ec);
  if (!fs::exists(st)) return Status::ok();
  if (!fs::is_directory(st))
    return Error::usage("--report '" + dir + "' exists and is not a folder: name a folder for the report");
  std::vector<fs::path> owned;
  for (const char* f : kReportFiles)
    if (fs::exists(fs::path(dir) / f, ec)) owned.push_back(fs::path(dir) / f);
  for (const char* f : kReportFolders)
    if (fs::exists(fs::path(dir) / f, ec)) owned.push_back(fs::path(dir) / f);
  if (owned.empty()) return Status::ok();
  // Every file the report would replace, checked against the inputs first: nothing is removed (or written over)
  // when one of them is read.
  std::vector<fs::path> files;
  for (const fs::path& p : owned) {
    if (!fs::is_directory(p, ec)) {
      files.push_back(p);
      continue;
    }
    for (auto it = fs::recursive_directory_iterator(p, ec); !ec && it != fs::recursive_directory_iterator();
         it.increment(ec))
      if (!it->is_directory(ec)) files.push_back(it->path());
  }
  for (const fs::path& f : files)
    if (Status s = inputs.check(f.string(), "--report"); !s)
      return Error::usage("--report '" + dir + "': " + f.string() + " is one of this run's inputs, in a file or folder "
                          "the report replaces: copy it elsewhere or give --report another folder");
  std::ifstream page(fs::path(dir) / "index.html");
  const std::string text((std::istreambuf_iterator<char>(page)), std::istreambuf_iterator<char>());
  if (text.find("Written by compare ") == std::string::npos)
    return Error::usage("--report '" + dir + "' holds " + owned.front().filename().string() +
                        " but no earlier report of compare (index.html): the report's files would mix with these; give "
                        "--report a new or empty folder");
  for (const fs::path& p : owned) {
    fs::remove_all(p, ec);
    if (ec) return Error::output(p.string(), "cannot remove this file of the earlier report (" + ec.message() +
                                                 "): remove it, or give --report another folder");
  }
  if (hooks.log) hooks.log("removed the earlier report in " + dir + " (index.html, metrics, video, pictures/, plots/, "
                           "maps/, profiles/)");
  return Status::ok();
}

}  // namespace

Expected<CompareRun> run_compare(const ComparisonSetup& setup, const Thresholds& thresholds,
                                 const CompareOutputs& o, const ComparisonHooks& base_hooks) {
  const bool merging = !o.merge.empty();
  if (merging && (!o.pictures.png_dir.empty() || !o.pictures.report_dir.empty() || !setup.error_maps.empty()))
    return Error::usage("--merge reads per-frame numbers only: --png, --report and --error-maps need the frames; "
                        "give them to the shards' own runs, or compare the whole sequence once");
  if (!merging && (setup.reference.empty() || setup.tests.empty()))
    return Error::usage("give --reference REF.####.exr and at least one test sequence (or --merge A.csv B.csv ...)");
  if (auto st = check_threshold_setup(setup, thresholds); !st) return st.error();
  if (auto st = check_speed_metric(setup); !st) return st.error();
  if (!o.plot.empty())
    if (auto f = chart_format(o.plot); !f) return f.error();
  // No output may replace a file this run reads (error maps and pictures are checked as they are written).
  Expected<ProtectedInputs> inputs = merging ? Expected<ProtectedInputs>(ProtectedInputs{}) : comparison_inputs(setup);
  if (!inputs) return inputs.error();
  for (const auto& m : o.merge) inputs->add(m);
  for (const auto& [path, option] : {std::pair{o.csv, "--csv"}, std::pair{o.json, "--json"}, std::pair{o.plot, "--plot"}})
    if (!path.empty())
      if (auto st = inputs->check(path, option); !st) return st.error();
  const bool report_on = !o.pictures.report_dir.empty();
  const std::string page = report_on ? (fs::path(o.pictures.report_dir) / "index.html").string() : std::string();
  const std::string report_csv = report_on ? (fs::path(o.pictures.report_dir) / "metrics.csv").string() : std::string();
  const std::string report_json = report_on ? (fs::path(o.pictures.report_dir) / "metrics.json").string() : std::string();
  for (const auto& path : {page, report_csv, report_json})
    if (!path.empty())
      if (auto st = inputs->check(path, "--report"); !st) return st.error();
  // No two outputs may name one file (--csv m.txt --json m.txt lost the CSV), and an existing output must be a
  // regular file (a device node given as --csv was replaced by one): refused before anything runs (issue 26 items 2
  // and 5), with the rule every tool's outputs follow (OutputPaths, temporal/io/runner.h).
  OutputPaths outputs;
  for (const auto& [path, option] : {std::pair{o.csv, "--csv"}, std::pair{o.json, "--json"}, std::pair{o.plot, "--plot"},
                                     std::pair{page, "--report"}, std::pair{report_csv, "--report"},
                                     std::pair{report_json, "--report"}})
    if (!path.empty())
      if (auto st = outputs.add(path, option); !st) return st.error();

  if (report_on)
    if (auto st = clear_earlier_report(o.pictures.report_dir, *inputs, base_hooks); !st) return st.error();

  CompareRun run;
  ComparisonHooks hooks = base_hooks;
  std::unique_ptr<ComparisonPictures> pictures;
  if (!o.pictures.png_dir.empty() || report_on) {
    auto p = ComparisonPictures::create(o.pictures, setup, &*inputs);
    if (!p && p.error().kind == ErrorKind::Usage) return p.error();
    if (!p) run.output_errors.push_back(p.error());  // e.g. no font: the metrics are still measured and written
    else {
      pictures = std::move(*p);
      pictures->attach(hooks);
    }
  }

  auto report = merging ? merge_comparison_csvs(o.merge, setup) : compare_sequences(setup, hooks);
  if (!report) return report.error();
  run.report = std::move(*report);
  run.failures = check_thresholds(run.report, thresholds);
  run.table = summary_table(run.report);
  auto keep = [&](const Status& st, const std::string& path) {
    if (!st) run.output_errors.push_back(st.error());
    else if (hooks.log) hooks.log("wrote " + path);
  };
  if (!o.csv.empty()) keep(write_comparison_csv(run.report, o.csv), o.csv);
  if (!o.json.empty())
    keep(write_comparison_json(run.report, thresholds, run.failures, setup.tool, setup.parameters, o.json), o.json);
  if (report_on) {
    keep(write_comparison_csv(run.report, report_csv), report_csv);
    keep(write_comparison_json(run.report, thresholds, run.failures, setup.tool, setup.parameters, report_json), report_json);
  }

  std::vector<ReportImage> charts;
  write_charts(run.report, o, *inputs, hooks, run, report_on ? &charts : nullptr);

  std::optional<PictureProducts> products;
  if (pictures) {
    auto p = pictures->finish(run.report);
    if (!p && p.error().kind == ErrorKind::Usage) return p.error();
    if (!p) run.output_errors.push_back(p.error());
    else {
      products = std::move(*p);
      for (const auto& e : products->errors) run.output_errors.push_back(e);
      if (hooks.log)
        for (const auto& f : products->written) hooks.log("wrote " + f);
    }
  }
  if (!report_on) return run;

  HtmlReport page_content;
  page_content.title = o.title.empty() ? "compare: " + fs::path(setup.reference).filename().string() : o.title;
  page_content.generator = setup.tool;
  page_content.command_line = setup.parameters;
  page_content.comparison = &run.report;
  page_content.failures = run.failures;
  page_content.notes = speed_notes(run.report);
  page_content.files = {{"metrics.csv", "metrics.csv"}, {"metrics.json", "metrics.json"}};
  // Page order: what a reader looks at first (the sheet and the video), then the maps, the charts, the rest.
  std::vector<ReportSection> sections;
  if (!charts.empty())
    sections.push_back({"plots", "Plots", "Per-frame metrics and speed against error (the method's own compute time "
                        "only). Each opens full size; the CSV holds the numbers.", charts});
  if (products)
    for (auto& s : products->sections) sections.push_back(std::move(s));
  for (const char* id : {"sheet", "flip", "error", "plots", "profiles", "gbuffer"})
    for (auto& s : sections)
      if (s.id == id) page_content.sections.push_back(std::move(s));
  if (products) {
    page_content.video = products->video;
    page_content.video_poster = products->video_poster;
    page_content.video_caption = products->video_caption;
    page_content.video_width = products->video_width;
    page_content.video_height = products->video_height;
  }
  if (auto st = write_html_report(page_content, page); !st) run.output_errors.push_back(st.error());
  else {
    run.report_page = page;
    if (hooks.log) hooks.log("wrote " + page);
  }
  return run;
}

}  // namespace temporal
