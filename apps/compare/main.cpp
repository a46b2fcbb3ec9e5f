// compare: per-frame PSNR, SSIM, flicker and (with --flip) FLIP of test sequences against a reference, as CSV,
// JSON, error-map EXRs, charts, pictures and an HTML report, with pass/fail thresholds for pipelines. The run
// lives in libtemporal (temporal/report/compare_run.h; the metrics in temporal/compare/comparison.h);
// docs/compare.md defines them. This file binds options.
#include "tool.h"

#include "temporal/report/compare_run.h"

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
                  "JSON summary, error-map EXRs, charts, pictures and an HTML report.\n"
                  "Typical use: compare --reference REF.####.exr TEST.####.exr [TEST2.####.exr ...] [--names a,b] "
                  "--flip ldr --report DIR");
  auto& app = tool.app();

  ComparisonSetup setup;
  CompareOutputs out;
  PictureOptions& pic = out.pictures;
  std::string frames, peak = "1", fail_on = "mean", profile = "row", flip = flip_mode_name(setup.flip), regions = "none";
  std::vector<std::string> crops;
  std::optional<int> sheet_frame;
  tool.add_params({Param::list("tests", "Test sequences (one or more), e.g. taa.####.exr phlm.####.exr", &setup.tests)});
  Param merge = Param::list("--merge",
                            "Instead of comparing: merge per-shard CSVs of one comparison (disjoint --frames ranges) "
                            "into --csv/--json/--plot; the means and intervals equal a single run's exactly",
                            &out.merge);
  merge.excludes = {"--reference"};
  tool.add_params(
      {
          Param::text("--reference", "Reference sequence, e.g. ref.####.exr (not with --merge)", &setup.reference),
          merge,
          Param::list("--names", "Comma-separated names of the test sequences (default: file names)", &setup.names, ','),
          Param::text("--gbuffer", "G-buffer sequence with `motion` (at the reference's size): motion-compensated flicker",
                      &setup.gbuffer),
          Param::text("--mask",
                      "Mask layer or channel (> 0.5 = inside) to report metrics inside and outside it; looked up in "
                      "each test, then the G-buffer, then the reference",
                      &setup.mask),
          Param::text("--layer", "Layer compared: rgb (the bare R,G,B) or a layer name (NAME.*)", &setup.layer),
          Param::text("--reference-layer",
                      "Layer of the reference to compare with (default: same as --layer), e.g. reference",
                      &setup.reference_layer),
          Param::text("--frames", "Frames A-B (default: every reference frame on disk)", &frames),
      },
      "Inputs");
  tool.add_params(
      {
          Param::flag_on("--latency-aware",
                         "Also score each test frame t against the reference frame t + L shown at the same instant, L = "
                         "the test's temporal:latencyFrames (psnr_latency; psnr_rgb stays the latency-free score; "
                         "docs/conventions.md, Latency)",
                         &setup.latency_aware),
          Param::integer("--warmup",
                         "The first N frames are summarised apart from the steady state (JSON `warmup`, `steady`)",
                         &setup.warmup_frames, 0, 1000000),
          Param::text("--peak",
                      "Peak value L for PSNR and SSIM, in pixel units; `max` = idiff's rule per frame (largest value, "
                      "at least 1)",
                      &peak),
          Param::choice("--flip",
                        "FLIP per frame: off; ldr = LDR-FLIP of the display-encoded frames (sRGB of the values clamped "
                        "to [0,1]); hdr = HDR-FLIP of the scene-linear values (ACES, automatic exposures). Off by "
                        "default: it costs about as much as PSNR and SSIM together (LDR) or more (HDR)",
                        &flip, {"off", "ldr", "hdr"}),
          Param::real("--ppd",
                      "FLIP's viewing condition in pixels per degree of visual angle (default: 0.7 m from a 0.7 m "
                      "wide 3840-pixel screen; FLIP's filters grow with it)",
                      &setup.flip_options.pixels_per_degree, kFlipMinPixelsPerDegree, kFlipMaxPixelsPerDegree),
          Param::choice("--regions",
                        "Every metric also per region: motion = static (zero motion, history, reference unchanged for "
                        "--static-frames frames), moving, disoccluded (the reprojection's depth/id test fails), from "
                        "--gbuffer (motion, depth, id). CSV rows per region, JSON `regions`, a region table",
                        &regions, {"none", "motion"}),
          Param::integer("--static-frames",
                         "Frames the reference must have been unchanged (and the pixel still, with history) for the "
                         "pixel to be static",
                         &setup.region_options.static_frames, 1, 65535),
          Param{.flag = "--static-tolerance",
                .help = "Largest frame-to-frame change of the reference's luminance (pixel units) that counts as "
                        "unchanged for the static region (noise of a Monte-Carlo reference)",
                .value = &setup.region_options.static_tolerance,
                .min = 0.0,
                .max = 1e6},
          Param::text("--speed-metric",
                      "Metric judged against compute time: the speed chart's y axis and the JSON's `pareto` flags "
                      "(compare --list-metrics)",
                      &setup.speed_metric),
      },
      "Metrics");
  tool.add_params(
      {
          Param::text("--csv", "Per-frame metrics CSV to write", &out.csv),
          Param::text("--json", "JSON summary to write (mean with 95% interval per sequence, paired differences, Pareto "
                                "front)", &out.json),
          Param::text("--plot",
                      "Charts F.EXT, EXT = png, svg or pdf: F (PSNR per frame), F-psnr-y, F-ssim, F-flicker, F-flip "
                      "(with --flip), F-psnr-latency (with --latency-aware), F-speed (--speed-metric against the "
                      "methods' own compute time); with --regions motion F-regions and F-psnr-static, -moving, "
                      "-disoccluded",
                      &out.plot),
          Param::text("--title", "Title of the charts, the contact sheet and the report (e.g. the scene)", &out.title),
          Param::text("--error-maps",
                      "Folder for error-map EXRs NAME.####.exr (error.R/G/B/Y, error.ssim, error.flicker, error.flip "
                      "with --flip, error.invalid)",
                      &setup.error_maps),
      },
      "Outputs");
  tool.add_params(
      {
          Param::text("--report",
                      "Folder for an offline HTML report (index.html): tables, charts, contact sheet, FLIP and error "
                      "maps, temporal profiles, side-by-side video (ffmpeg)",
                      &pic.report_dir),
          Param::text("--png",
                      "Folder for pictures of every frame: reference and tests display-encoded, FLIP and error heat "
                      "maps, G-buffer; and the contact sheet and profiles",
                      &pic.png_dir),
          Param::text("--png-format", "Format of the --png pictures: png or jpg", &pic.png_format),
          Param::optional("--sheet-frame", "Frame of the contact sheet (default: the last compared frame)", &sheet_frame),
          Param::list("--crop",
                      "Region x,y,w,h (pixels) zoomed on the contact sheet; repeat for more (default: the two regions "
                      "of largest FLIP, else error)",
                      &crops),
          Param::text("--profile",
                      "Line of the temporal profiles: row:Y (x-t image), column:X (y-t), row or column (the middle)",
                      &profile),
          Param{.flag = "--exposure",
                .help = "Exposure of the pictures in stops (values x 2^E before encoding)",
                .value = &pic.display.exposure,
                .min = -64.0,  // 2^E stays a normal float
                .max = 64.0},
          Param::text("--display",
                      "Display colour space of the pictures (OCIO config: srgb_display, gamma22_display, ...)",
                      &pic.display.display),
          Param::text("--ocio", "OpenColorIO config for --display (default: $OCIO, else the built-in one)",
                      &pic.display.ocio),
      },
      "Pictures");
  for (const std::string* file : {&out.csv, &out.json, &out.plot}) tool.add_output(file);
  for (const std::string* folder : {&setup.error_maps, &pic.report_dir, &pic.png_dir}) tool.add_output(folder, true);
  // One --fail-<option> per registry metric that has a threshold.
  std::map<std::string, std::optional<double>> fail;
  std::string fail_list;
  ParamList thresholds_params;
  for (const auto& d : metric_registry()) {
    if (d.threshold_option.empty()) continue;
    thresholds_params.push_back(Param::optional("--fail-" + d.threshold_option, d.threshold_help, &fail[d.name], -1e6, 1e6));
    fail_list += (fail_list.empty() ? "--fail-" : ", --fail-") + d.threshold_option;
  }
  bool fail_nonfinite = false;
  thresholds_params.push_back(Param::flag_on(
      "--fail-nonfinite",
      "Exit 3 when a test frame holds NaN/Inf pixels or values whose squared error overflows (PSNR -inf)",
      &fail_nonfinite));
  thresholds_params.push_back(Param::choice(
      "--fail-on", "What the thresholds judge: each sequence's mean over frames, or its worst frame", &fail_on,
      {"mean", "worst"}));
  tool.add_params(thresholds_params, "Thresholds");
  auto list = [&app](const char* flag, const char* help, std::string (*text)()) {
    app.add_flag_callback(
           flag,
           [text] {
             std::fputs(text().c_str(), stdout);
             throw CLI::Success();
           },
           help)
        ->group("Metrics");
  };
  list("--list-metrics", "List the metrics (tab-separated: name, label, unit, better = higher|lower) and exit",
       metric_list_text);
  list("--list-metrics-json", "List the metrics as a JSON array (name, label, unit, better, CSV columns, threshold "
       "option, range) and exit", metric_list_json);
  app.footer("Exit codes: 0 success (thresholds passed), 1 usage error, 2 input error (missing, corrupt or mismatched "
             "files, missing layers), 3 a threshold (" + fail_list + ") failed, 4 output error (including charts, "
             "pictures or a video that cannot be made: CSV and JSON are still written), 5 internal error.\n"
             "Without DISPLAY, compare starts its own Xvfb for the charts (--verbose says so). Definitions: "
             "docs/compare.md; conventions: docs/conventions.md");

  bool threshold_failed = false;
  const int code = tool.run(argc, argv, [&]() -> Status {
    if (!frames.empty()) {
      auto range = FrameRange::parse(frames);
      if (!range) return range.error();
      setup.frames = *range;
    }
    if (auto st = set_peak(peak, setup); !st) return st;
    setup.regions = regions == "motion";
    setup.flip = flip == "ldr" ? FlipMode::Ldr : flip == "hdr" ? FlipMode::Hdr : FlipMode::Off;  // checked: a choice
    for (const auto& c : crops) {
      auto rect = parse_crop(c);
      if (!rect) return rect.error();
      pic.crops.push_back(*rect);
    }
    auto line = parse_profile_line(profile);
    if (!line) return line.error();
    pic.profile = *line;
    pic.sheet_frame = sheet_frame;
    pic.title = out.title;
    setup.tool = tool.signature();
    setup.parameters = tool.command_line();
    Thresholds thresholds;
    thresholds.worst_frame = fail_on == "worst";
    thresholds.nonfinite = fail_nonfinite;
    for (const auto& [metric, limit] : fail)
      if (limit) thresholds.limits[metric] = *limit;

    auto run = run_compare(setup, thresholds, out, tool.hooks());
    if (!run) return run.error();
    std::fputs(run->table.c_str(), stdout);
    std::fflush(stdout);
    for (const auto& e : run->output_errors) tool.print_error(e);
    for (const auto& f : run->failures) std::cerr << "compare: threshold failed: " << f.message() << "\n";
    threshold_failed = !run->failures.empty();
    if (!run->output_errors.empty())
      return Status(Error{run->output_errors.front().kind, {}, "some outputs were not written (see above)"});
    return Status::ok();
  });
  if (code == tool::kExitOk && threshold_failed) return tool::kExitThreshold;
  return code;
}
