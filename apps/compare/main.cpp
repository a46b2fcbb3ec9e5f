// compare: per-frame PSNR, SSIM, flicker and (with --flip) FLIP of test sequences against a reference, as CSV,
// JSON, error-map EXRs and VTK plots, with pass/fail thresholds for pipelines. The metrics and their registry
// live in libtemporal (temporal/metrics/comparison.h); docs/compare.md defines them. This file binds options.
#include "tool.h"

#include "temporal/metrics/comparison.h"
#include "temporal/plot/plot.h"

#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <optional>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  using namespace temporal;
  tool::Tool tool("compare",
                  "Measures test sequences against a reference, frame by frame: PSNR (all compared channels and "
                  "luminance), SSIM (Wang et al. 2004, on luminance), temporal instability (flicker: RMS "
                  "difference between the test's and the reference's frame-to-frame change, motion-compensated "
                  "with --gbuffer) and, with --flip, FLIP (Andersson et al. 2020, 2021). Writes a per-frame CSV, a "
                  "JSON summary, error-map EXRs and PNG charts.\n"
                  "Typical use: compare --reference REF.####.exr TEST.####.exr [TEST2.####.exr ...] [--names a,b] "
                  "--csv F.csv --json F.json --plot F.png");
  auto& app = tool.app();

  ComparisonSetup setup;
  std::string csv, json, plot, frames, peak = "1";
  std::string fail_on = "mean";
  std::vector<std::string> merge;
  app.add_option("--reference", setup.reference, "Reference sequence, e.g. ref.####.exr (not with --merge)");
  app.add_option("tests", setup.tests, "Test sequences (one or more), e.g. taa.####.exr phlm.####.exr");
  app.add_option("--merge", merge,
                 "Instead of comparing: merge per-shard CSVs of one comparison (disjoint --frames ranges) into "
                 "--csv/--json/--plot; the means and intervals equal a single run's exactly")
      ->excludes("--reference");
  app.add_option("--names", setup.names, "Comma-separated names of the test sequences (default: file names)")
      ->delimiter(',')->default_str("");
  app.add_option("--csv", csv, "Per-frame metrics CSV to write");
  app.add_option("--json", json, "JSON summary to write (mean/min/max per sequence, thresholds)");
  app.add_option("--plot", plot,
                 "PNG charts: F.png (PSNR per frame), F-psnr-y.png, F-ssim.png, F-flicker.png, F-flip.png (with "
                 "--flip), F-speed.png (PSNR against the compute time found in the test headers)");
  app.add_option("--gbuffer", setup.gbuffer,
                 "G-buffer sequence with `motion` (at the reference's size): motion-compensated flicker");
  app.add_option("--mask", setup.mask,
                 "Mask layer or channel (> 0.5 = inside) to report metrics inside and outside it; looked up in each "
                 "test, then the G-buffer, then the reference");
  app.add_option("--layer", setup.layer, "Layer compared: rgb (the bare R,G,B) or a layer name (NAME.*)");
  app.add_option("--reference-layer", setup.reference_layer,
                 "Layer of the reference to compare with (default: same as --layer), e.g. reference");
  app.add_option("--error-maps", setup.error_maps,
                 "Folder for error-map EXRs NAME.####.exr (error.R/G/B/Y, error.ssim, error.flicker, error.flip "
                 "with --flip, error.invalid)");
  app.add_option("--frames", frames, "Frames A-B (default: every reference frame on disk)");
  app.add_option("--warmup", setup.warmup_frames,
                 "The first N frames are summarised apart from the steady state (JSON `warmup`, `steady`)")
      ->check(CLI::Range(0, 1000000));
  app.add_option("--peak", peak,
                 "Peak value L for PSNR and SSIM, in pixel units; `max` = idiff's rule per frame (largest value, "
                 "at least 1)");
  const std::map<std::string, FlipMode> flip_modes = {{"off", FlipMode::Off}, {"ldr", FlipMode::Ldr}, {"hdr", FlipMode::Hdr}};
  app.add_option("--flip", setup.flip,
                 "FLIP per frame: off; ldr = LDR-FLIP of the display-encoded frames (sRGB of the values clamped to "
                 "[0,1]); hdr = HDR-FLIP of the scene-linear values (ACES, automatic exposures). Off by default: it "
                 "costs about as much as PSNR and SSIM together (LDR) or more (HDR)")
      ->transform(CLI::CheckedTransformer(flip_modes).description(""))
      ->type_name("off|ldr|hdr")
      ->default_str(flip_mode_name(setup.flip));
  app.add_option("--ppd", setup.flip_options.pixels_per_degree,
                 "FLIP's viewing condition in pixels per degree of visual angle (default: 0.7 m from a 0.7 m wide "
                 "3840-pixel screen)");
  // One --fail-<option> per registry metric that has a threshold.
  std::map<std::string, std::optional<double>> fail;
  std::string fail_list;
  for (const auto& d : metric_registry()) {
    if (d.threshold_option.empty()) continue;
    app.add_option("--fail-" + d.threshold_option, fail[d.name], d.threshold_help);
    fail_list += (fail_list.empty() ? "--fail-" : ", --fail-") + d.threshold_option;
  }
  bool fail_nonfinite = false;
  app.add_flag("--fail-nonfinite", fail_nonfinite,
               "Exit 3 when a test frame holds NaN/Inf pixels or values whose squared error overflows (PSNR -inf)");
  app.add_option("--fail-on", fail_on, "What the thresholds judge: each sequence's mean over frames, or its worst frame")
      ->check(CLI::IsMember({"mean", "worst"}));
  app.footer("Exit codes: 0 success (thresholds passed), 1 usage error, 2 input error (missing, corrupt or mismatched "
             "files, missing layers), 3 a threshold (" + fail_list + ") failed, 4 output error (including plots that "
             "cannot be drawn: CSV and JSON are still written), 5 internal error.\n"
             "Without DISPLAY, compare starts its own Xvfb for the plots (--verbose says so). Definitions: "
             "docs/compare.md; conventions: docs/conventions.md");

  bool threshold_failed = false;
  const int code = tool.run(argc, argv, [&]() -> Status {
    if (!frames.empty()) {
      auto range = FrameRange::parse(frames);
      if (!range) return range.error();
      setup.frames = *range;
    }
    if (peak == "max") {
      setup.peak_from_data = true;
    } else {
      char* end = nullptr;
      setup.peak = std::strtod(peak.c_str(), &end);
      if (end == peak.c_str() || *end != '\0' || !(setup.peak > 0.0) || !std::isfinite(setup.peak))
        return Error::usage("--peak '" + peak + "' is not a positive number or `max`");
    }
    setup.tool = tool.signature();
    setup.parameters = tool.command_line();
    Thresholds thresholds;
    thresholds.worst_frame = fail_on == "worst";
    thresholds.nonfinite = fail_nonfinite;
    for (const auto& [metric, limit] : fail)
      if (limit) thresholds.limits[metric] = *limit;
    if (auto st = check_threshold_setup(setup, thresholds); !st) return st;

    if (merge.empty() && (setup.reference.empty() || setup.tests.empty()))
      return Error::usage("give --reference REF.####.exr and at least one test sequence (or --merge A.csv B.csv ...)");
    // No output may replace a file this run reads (error maps are checked by the engine).
    ProtectedInputs inputs;
    if (merge.empty()) {
      auto found = comparison_inputs(setup);
      if (!found) return found.error();
      inputs = std::move(*found);
    }
    for (const auto& m : merge) inputs.add(m);
    for (const auto& [path, option] : {std::pair{csv, "--csv"}, std::pair{json, "--json"}, std::pair{plot, "--plot"}})
      if (!path.empty())
        if (auto st = inputs.check(path, option); !st) return st;
    auto report = merge.empty() ? compare_sequences(setup, tool.hooks()) : merge_comparison_csvs(merge, setup);
    if (!report) return report.error();
    const auto failures = check_thresholds(*report, thresholds);

    std::optional<Error> output_error;
    auto keep = [&](const Status& st) {
      if (!st && !output_error) output_error = st.error();
      if (!st) tool.print_error(st.error());
    };
    if (!csv.empty()) keep(write_comparison_csv(*report, csv));
    if (!json.empty())
      keep(write_comparison_json(*report, thresholds, failures, tool.signature(), tool.command_line(), json));
    std::fputs(summary_table(*report).c_str(), stdout);
    std::fflush(stdout);

    if (!plot.empty()) {
      auto display = VirtualDisplay::ensure();
      if (!display) {
        keep(Status(Error::output(plot, display.error().message)));
      } else {
        if (display->started()) tool.log("DISPLAY is not usable: started Xvfb on " + display->display() + " for the plots");
        for (const auto& [path, chart] : comparison_charts(*report, plot)) {
          if (auto st = inputs.check(path, "--plot"); !st) return st;
          keep(write_chart_png(chart, path));
          tool.log("wrote " + path);
        }
      }
    }
    for (const auto& f : failures) std::cerr << "compare: threshold failed: " << f.message() << "\n";
    threshold_failed = !failures.empty();
    if (output_error) return Status(Error{output_error->kind, {}, "some outputs were not written (see above)"});
    return Status::ok();
  });
  if (code == tool::kExitOk && threshold_failed) return tool::kExitThreshold;
  return code;
}
