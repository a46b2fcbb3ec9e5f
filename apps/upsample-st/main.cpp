// upsample-st: rebuilds the full-resolution shading payload from 1/k-resolution jittered shading and the
// full-resolution G-buffer, with the methods of seed 000 (spatial, temporal, herzog) and seed 002 (drobot).
// The algorithms live in libtemporal (temporal/upsample/upsample.h); docs/upsample-st.md describes them.
#include "tool.h"

#include "temporal/core/exr.h"
#include "temporal/core/sequence.h"
#include "temporal/upsample/upsample.h"

#include <algorithm>
#include <cstdio>
#include <optional>
#include <set>
#include <sstream>
#include <string>

namespace {

std::vector<std::string> read_layers(const std::string& layer) {
  std::vector<std::string> out;
  std::stringstream in(layer.empty() ? std::string("rgb") : layer);
  std::string item;
  while (std::getline(in, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace temporal;
  namespace up = temporal::upsample;
  tool::Tool tool("upsample-st",
                  "Upsamples low-resolution jittered shading (the shade sequence of render-gbuffer) to the resolution of the "
                  "G-buffer: joint-bilateral (spatial), temporally-amortised (temporal) and spatio-temporal (herzog) "
                  "upsampling of Herzog et al. 2010, and the spatiotemporal framework of Drobot 2011 (drobot).\n"
                  "Usage: upsample-st --gbuffer G.####.exr --input shade.####.exr --out up.####.exr --method herzog");
  auto& app = tool.app();
  up::Options o;
  std::string gbuffer, input, out, method = "herzog", mode = "cache", layer = "rgb", frames, reset_frames,
                                   compression = "zip";
  bool no_ids = false, favor_spatial = false, depth_only = false, cache_point = false;
  app.add_option("--gbuffer", gbuffer, "Full-resolution G-buffer sequence (depth, N, motion, id), e.g. G.####.exr")
      ->required();
  app.add_option("--input", input,
                 "Low-resolution shading sequence (1/k per axis; jitter and k from its metadata), e.g. shade.####.exr")
      ->required();
  app.add_option("--out", out, "Output sequence, e.g. up.####.exr")->required();
  app.add_option("--method", method, "spatial | temporal | herzog | drobot")
      ->check(CLI::IsMember({"spatial", "temporal", "herzog", "drobot"}));
  app.add_option("--layer", layer, "Payload layers to upsample: rgb (bare R,G,B) or layer names, comma-separated");
  app.add_option("--frames", frames, "Frames A-B (default: every input frame on disk)");
  app.add_option("--reset-frames", reset_frames, "Frames where the history is discarded (camera cuts), e.g. 10,40-41");
  app.add_flag("--debug-layers", o.debug_layers,
               "Add debug.* layers: confidence, disocclusion, gradient, wf, historyWeight, convergence");
  app.add_option("--compression", compression, "EXR compression of the output: zip | none | piz");
  // seed 000
  app.add_option("--sigma-normal", o.sigma_normal, "sigma_n of the normal weight (seed 000 eq. 2)")
      ->check(CLI::PositiveNumber);
  app.add_option("--sigma-depth-fraction", o.sigma_depth_fraction,
                 "sigma_d as a fraction of clipFar - clipNear (seed 000: 3%)")
      ->check(CLI::PositiveNumber);
  app.add_option("--sigma-depth", o.sigma_depth, "Absolute sigma_d in world units (0: use the fraction)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--depth-tolerance", o.depth_tolerance,
                 "Relative depth difference above which a history sample is disoccluded")
      ->check(CLI::PositiveNumber);
  app.add_flag("--no-ids", no_ids, "Do not compare material ids in the disocclusion test (depth only)");
  app.add_option("--kernel-gamma", o.kernel_gamma,
                 "herzog: gamma of the image kernel k; the fall-off used is min(gamma * w_f, --max-kernel-gamma)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--max-kernel-gamma", o.max_kernel_gamma, "herzog: cap of gamma * w_f (seed 000: 4)")
      ->check(CLI::PositiveNumber);
  app.add_option("--min-kernel-gamma", o.min_kernel_gamma,
                 "herzog: floor of the fall-off (seed 000: 0, a flat kernel where w_f = 0; 1 gives a cone)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--a", o.a, "herzog: sensitivity a of eq. 8 (w_f = a (1 - |grad|)^2)")->check(CLI::Range(0.0, 1.0));
  app.add_flag("--favor-spatial", favor_spatial, "herzog: a = 0.7, as the paper's elephant scene");
  app.add_option("--gradient-scale", o.gradient_scale, "herzog: gradient kept at full/scale resolution (1, 2, 4)")
      ->check(CLI::IsMember({1, 2, 4, 8}));
  app.add_option("--gradient-mip-level", o.gradient_mip_level,
                 "herzog: mip level of the gradient's spatial low-pass (full-resolution levels)")
      ->check(CLI::Range(0.0, 8.0));
  app.add_option("--max-history-weight", o.max_history_weight, "herzog: bound of h_w (0: 2 k^2)")
      ->check(CLI::NonNegativeNumber);
  app.add_flag("--lagged-wf", o.lagged_wf,
               "herzog: eq. 7 with the previous frame's w_f (one pass instead of three; w_f reacts a frame later)");
  // seed 002
  app.add_option("--mode", mode, "drobot: cache (the framework, section 7.2) | refresh (Figure 7.12)")
      ->check(CLI::IsMember({"cache", "refresh"}));
  app.add_option("--normal-power", o.normal_power, "drobot: contrastCoef of Listing 7.1")->check(CLI::PositiveNumber);
  app.add_flag("--depth-only", depth_only, "drobot: depth weights only (no normals) in Listing 7.1");
  app.add_option("--miss-threshold", o.miss_threshold, "drobot: IN_MissThreshold of Listing 7.2 (relative depth)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--convergence-time", o.convergence_time, "drobot: IN_ConvergenceTime of Listing 7.2")
      ->check(CLI::PositiveNumber);
  app.add_option("--max-frames", o.max_frames, "drobot: frames in the exponential history (0: k^2)")
      ->check(CLI::NonNegativeNumber);
  app.add_flag("--cache-point", cache_point,
               "drobot: read the low-resolution cache with point instead of bilinear filtering (Figure 7.5)");
  app.add_option("--filter-amp", o.filter_amp, "drobot: IN_BilateralFilterAmp of Listing 7.3 (per relative depth)")
      ->check(CLI::NonNegativeNumber);
  // seed 000 section 4
  app.add_flag("--demodulate", o.demodulate,
               "Upsample lighting only: divide R,G,B by the G-buffer albedo, multiply the result back (section 4)");
  app.add_option("--aa-factor", o.aa_factor,
                 "Antialiasing variant: the G-buffer is m x m the output resolution; the result is downsampled")
      ->check(CLI::Range(1, 8));

  return tool.run(argc, argv, [&]() -> Status {
    auto m = up::parse_method(method);
    if (!m) return m.error();
    o.method = *m;
    auto dm = up::parse_drobot_mode(mode);
    if (!dm) return dm.error();
    o.drobot_mode = *dm;
    o.use_ids = !no_ids;
    o.drobot_normals = !depth_only;
    o.cache_bilinear = !cache_point;
    if (favor_spatial) o.a = 0.7f;
    auto comp = parse_compression(compression);
    if (!comp) return comp.error();
    if (*comp == ExrCompression::Dwaa) return Error::usage("--compression dwaa is lossy and refused for payload data");
    auto gpat = SequencePattern::parse(gbuffer);
    if (!gpat) return gpat.error();
    auto ipat = SequencePattern::parse(input);
    if (!ipat) return ipat.error();
    auto opat = SequencePattern::parse(out);
    if (!opat) return opat.error();
    if (ipat->has_placeholder() && !opat->has_placeholder())
      return Error::usage("--out '" + out + "' needs a frame placeholder (#### or %04d) for a sequence");
    std::optional<FrameRange> range;
    if (!frames.empty()) {
      auto r = FrameRange::parse(frames);
      if (!r) return r.error();
      range = *r;
    }
    auto list = resolve_frames(*ipat, range);
    if (!list) return list.error();
    std::set<int> resets;
    if (!reset_frames.empty()) {
      auto rl = parse_frame_list(reset_frames);
      if (!rl) return rl.error();
      resets.insert(rl->begin(), rl->end());
    }
    ExrWriteOptions wopt;
    wopt.compression = *comp;
    const ExrSelection gsel{up::gbuffer_layers(o)};
    const ExrSelection isel{read_layers(layer)};

    up::Upsampler upsampler(o);
    tool::Progress progress(tool.name(), int(list->size()));
    double total_ms = 0;
    std::size_t total_holes = 0, total_nonfinite = 0;
    int prev_frame = -1;
    for (const int frame : *list) {
      const std::string gpath = gpat->path(frame), ipath = ipat->path(frame), opath = opat->path(frame);
      auto g = read_exr(gpath, gsel);
      if (!g) return g.error();
      auto low = read_exr(ipath, isel);
      if (!low) return low.error();
      if (const std::size_t bad = up::count_non_finite_gbuffer(*g); bad > 0)
        tool.print_warning(gpath, std::to_string(bad) + " non-finite G-buffer values (NaN/Inf); those pixels get "
                                                        "no spatial weight and no history");
      auto channels = up::select_channels(*low, layer, ipath);
      if (!channels) return channels.error();
      // A gap in the frame list (--frames with holes is refused by resolve_frames) or a reset frame cuts.
      const bool cut = resets.count(frame) > 0 || (prev_frame >= 0 && frame != prev_frame + 1);
      up::FrameStats stats;
      auto result = upsampler.process(*g, *low, *channels, cut, &stats, {gpath, ipath});
      if (!result) {
        Error e = result.error();
        if (e.file.empty()) e.file = ipath;
        return e;
      }
      Image& img = **result;
      FrameMetadata md = g->metadata();
      md.jitter.reset();
      md.jitter_factor.reset();
      md.jitter_index.reset();
      md.compute_ms = stats.compute_ms;
      md.tool = tool.signature();
      md.parameters = tool.command_line();
      for (const auto& [name, ms] : low->metadata().timings_ms) md.timings_ms[name] = ms;
      md.timings_ms["upsample"] = stats.compute_ms;
      md.camera_cut = stats.history_reset;
      md.extra["method"] = method + (o.method == up::Method::Drobot ? "-" + mode : "");
      md.extra["holePixels"] = std::to_string(stats.hole_pixels);
      md.extra["historyPixels"] = std::to_string(stats.history_pixels);
      md.extra["nonFiniteInput"] = std::to_string(stats.non_finite_input);
      img.metadata() = md;
      if (stats.non_finite_input > 0)
        tool.print_warning(ipath, std::to_string(stats.non_finite_input) +
                                      " non-finite payload values (NaN/Inf): treated as missing samples, kept out of "
                                      "the history");
      if (Status st = write_exr(opath, img, wopt); !st) return st;
      total_ms += stats.compute_ms;
      total_holes += stats.hole_pixels;
      total_nonfinite += stats.non_finite_input;
      char line[256];
      std::snprintf(line, sizeof line, "frame %d: %.2f ms, %zu pixels without history, %zu non-finite inputs%s", frame,
                    stats.compute_ms, stats.hole_pixels, stats.non_finite_input,
                    stats.history_reset ? " (history reset)" : "");
      tool.log(line);
      progress.step(frame);
      prev_frame = frame;
    }
    char line[256];
    std::snprintf(line, sizeof line, "%zu frames, %.2f ms per frame (upsampling only), %zu pixels without history, "
                  "%zu non-finite inputs", list->size(), total_ms / double(list->size()), total_holes, total_nonfinite);
    tool.log(line);
    return Status::ok();
  });
}
