// filter-phlm: temporal filtering of a 1-spp frame sequence with pixel history linear models (seed 003) and
// the baselines of its Table 2 (TAA after Karis 2014, FXAA after Lottes 2011) plus the exponential history of
// its eq. 1. Options, defaults and every choice: docs/filter-phlm.md.
#include "tool.h"

#include "temporal/phlm/ema.h"
#include "temporal/core/exr.h"
#include "temporal/phlm/fxaa.h"
#include "temporal/phlm/phlm.h"
#include "temporal/core/sequence.h"
#include "temporal/phlm/taa.h"

#include <algorithm>
#include <chrono>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace {

using namespace temporal;

struct Options {
  std::string input, gbuffer, out, method = "phlm", layer = "rgb", frames, state_in, state_out, reset_frames;
  std::string compression = "zip";
  bool debug = false;
  PhlmParams phlm;
  TaaParams taa;
  EmaParams ema;
  FxaaParams fxaa;
};

std::string description() {
  return "Temporal filtering of a 1-spp sequence: pixel history linear models (seed 003, --method phlm) and the "
         "baselines taa (Karis 2014), ema (seed 003 eq. 1) and fxaa (Lottes 2011).\n"
         "State per pixel (persistent, kept across frames; --state-out writes it):\n"
         "  phlm, 3 channels: " +
         std::to_string(phlm_state_floats(3) * 4) + " bytes (beta 3x4 = 12, P 4x4 as UD factors = 10, feature 3, "
         "scale 1 floats)\n"
         "  phlm, 1 channel (--layer ssao): " +
         std::to_string(phlm_state_floats(1) * 4) +
         " bytes (beta 1x2, P 2x2 as UD factors = 3, feature 1, scale 1 floats)\n"
         "  taa: 12 bytes (RGB history); ema: 12 bytes + 8 with a G-buffer (previous depth and id); fxaa: none\n"
         "Double buffering (read the previous models at p + motion, write the new ones) holds twice that in memory.";
}

// Channels of the filtered layer: R,G,B for `rgb`, else every `NAME.*` channel.
Expected<std::vector<std::string>> layer_channels(const Image& img, const std::string& layer, const std::string& file) {
  std::vector<std::string> names;
  if (layer == "rgb") {
    names = {"R", "G", "B"};
  } else {
    names = img.layer_channels(layer);
  }
  for (const auto& n : names)
    if (!img.plane(n))
      return Error::input(file, "no float channel '" + n + "' for --layer " + layer + "; pick a layer the file has");
  if (names.size() != 1 && names.size() != 3)
    return Error::usage("--layer " + layer + " has " + std::to_string(names.size()) +
                        " channels; the filters take 1 (e.g. ssao) or 3 (rgb, direct)");
  return names;
}

Status run(tool::Tool& tool, const Options& o) {
  const std::set<std::string> methods = {"phlm", "taa", "ema", "fxaa"};
  if (!methods.count(o.method)) return Error::usage("--method must be phlm, taa, ema or fxaa (got " + o.method + ")");
  if (o.method == "fxaa" && (!o.state_in.empty() || !o.state_out.empty()))
    return Error::usage("--method fxaa is spatial and has no state: drop --state-in / --state-out");
  auto input = SequencePattern::parse(o.input);
  if (!input) return input.error();
  auto out = SequencePattern::parse(o.out);
  if (!out) return out.error();
  if (!out->has_placeholder() && input->has_placeholder())
    return Error::usage("--out needs a frame placeholder (e.g. filtered.####.exr) like --input");
  std::optional<SequencePattern> gbuffer;
  if (!o.gbuffer.empty()) {
    auto g = SequencePattern::parse(o.gbuffer);
    if (!g) return g.error();
    gbuffer = *g;
  }
  std::optional<SequencePattern> state_out;
  if (!o.state_out.empty()) {
    auto s = SequencePattern::parse(o.state_out);
    if (!s) return s.error();
    state_out = *s;
  }
  std::optional<FrameRange> range;
  if (!o.frames.empty()) {
    auto r = FrameRange::parse(o.frames);
    if (!r) return r.error();
    range = *r;
  }
  std::set<int> reset_frames;
  if (!o.reset_frames.empty()) {
    auto list = parse_frame_list(o.reset_frames);
    if (!list) return list.error();
    reset_frames.insert(list->begin(), list->end());
  }
  auto compression = parse_compression(o.compression);
  if (!compression) return compression.error();
  if (*compression == ExrCompression::Dwaa) return Error::usage("--compression dwaa is lossy; use none, zip or piz");
  ExrWriteOptions write_options;
  write_options.compression = *compression;

  auto frames = resolve_frames(*input, range);
  if (!frames) return frames.error();

  PhlmFilter phlm(o.phlm);
  TaaFilter taa(o.taa);
  EmaFilter ema(o.ema);

  const std::vector<std::string> layer_sel = {o.layer == "rgb" ? std::string("rgb") : o.layer};
  bool state_loaded = false;
  Image output;
  tool::Progress progress(tool.name(), int(frames->size()));
  std::size_t total_non_finite = 0;

  auto write_state = [&](int frame) -> Status {
    if (!state_out) return Status::ok();
    Image state = o.method == "phlm" ? phlm.state_with_covariance()
                                     : (o.method == "taa" ? taa.state() : ema.state());
    state.metadata().frame = frame;
    state.metadata().tool = tool.signature();
    state.metadata().parameters = tool.command_line();
    state.metadata().extra["phlmStateOf"] = o.method;
    const std::string path = state_out->path(frame);
    return write_exr(path, state, write_options);
  };

  for (std::size_t fi = 0; fi < frames->size(); ++fi) {
    const int frame = (*frames)[fi];
    const std::string in_path = input->path(frame);
    auto color = read_exr(in_path, ExrSelection{layer_sel});
    if (!color) return color.error();
    auto channels = layer_channels(*color, o.layer, in_path);
    if (!channels) return channels.error();

    if (fi == 0 && !o.state_in.empty()) {
      std::vector<std::string> names;
      if (o.method == "phlm") names = PhlmFilter::state_channel_names(int(channels->size()));
      auto state = read_exr(o.state_in);
      if (!state) return state.error();
      if (state->width() != color->width() || state->height() != color->height())
        return Error::input(o.state_in, "state is " + std::to_string(state->width()) + "x" +
                                            std::to_string(state->height()) + " but the input is " +
                                            std::to_string(color->width()) + "x" + std::to_string(color->height()));
      Status s = o.method == "phlm" ? phlm.set_state(*state, int(channels->size()))
                                    : (o.method == "taa" ? taa.set_state(*state, int(channels->size()))
                                                         : ema.set_state(*state, int(channels->size())));
      if (!s) {
        Error e = s.error();
        if (e.file.empty()) e.file = o.state_in;
        return e;
      }
      state_loaded = true;
    }

    FilterInput in;
    in.color = &*color;
    in.channels = *channels;
    in.debug = o.debug;
    in.jitter = color->metadata().jitter.value_or(glm::vec2(0.0f));
    in.reset = (fi == 0 && !state_loaded) || color->metadata().camera_cut.value_or(false) || reset_frames.count(frame);
    Image gb;
    if (gbuffer) {
      const std::string g_path = gbuffer->path(frame);
      std::vector<std::string> sel = {"motion"};
      if (o.method == "ema") sel = {"motion", "depth", "id"};
      auto g = read_exr(g_path, ExrSelection{sel});
      if (!g) return g.error();
      if (g->width() != color->width() || g->height() != color->height())
        return Error::input(g_path, "G-buffer is " + std::to_string(g->width()) + "x" + std::to_string(g->height()) +
                                        " but " + in_path + " is " + std::to_string(color->width()) + "x" +
                                        std::to_string(color->height()) + "; render both at the same --size");
      gb = std::move(*g);
      in.motion_x = gb.plane("motion.X");
      in.motion_y = gb.plane("motion.Y");
      if (!in.motion_x || !in.motion_y)
        return Error::input(g_path, "no layer 'motion'; render it with render-gbuffer --outputs gbuffer");
      if (o.method == "ema") {
        in.depth = gb.plane("depth.Z");
        in.id = gb.uint_plane("id");
      }
      if (gb.metadata().camera_cut.value_or(false) && fi > 0) in.reset = true;
    }

    FilterStats stats;
    const auto t0 = std::chrono::steady_clock::now();
    Status s;
    if (o.method == "phlm")
      s = phlm.process(in, output, &stats);
    else if (o.method == "taa")
      s = taa.process(in, output, &stats);
    else if (o.method == "ema")
      s = ema.process(in, output, &stats);
    else
      s = fxaa(in, output, o.fxaa, &stats);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (!s) {
      Error e = s.error();
      if (e.file.empty()) e.file = in_path;
      return e;
    }
    if (stats.non_finite > 0)
      tool.print_warning(in_path, std::to_string(stats.non_finite) +
                                      " pixels hold NaN or Inf; they were treated as missing and kept out of the "
                                      "history");
    total_non_finite += stats.non_finite;
    tool.log("frame " + std::to_string(frame) + ": " + std::to_string(ms) + " ms, resets " +
             std::to_string(stats.history_resets) + ", box " + std::to_string(stats.clamped) +
             (o.method == "phlm" ? ", max trace(P) " + std::to_string(stats.max_trace_p) : std::string()) +
             (in.reset ? " (history reset)" : ""));

    FrameMetadata& md = output.metadata();
    md.tool = tool.signature();
    md.parameters = tool.command_line();
    md.frame = frame;
    md.compute_ms = ms;
    md.timings_ms = {{"filter", ms}};  // the render passes' timings describe another stage's file
    md.extra["method"] = o.method;
    const std::string out_path = out->path(frame);
    if (Status w = write_exr(out_path, output, write_options); !w) return w;
    if (state_out && (state_out->has_placeholder() || fi + 1 == frames->size()))
      if (Status w = write_state(frame); !w) return w;
    progress.step(frame);
  }
  if (total_non_finite > 0)
    tool.log("non-finite input pixels in total: " + std::to_string(total_non_finite));
  return Status::ok();
}

}  // namespace

int main(int argc, char** argv) {
  temporal::tool::Tool tool("filter-phlm", description());
  Options o;
  auto& app = tool.app();
  app.add_option("--input", o.input, "Input sequence, e.g. color.####.exr (1 spp, scene-linear)")->required();
  app.add_option("--gbuffer", o.gbuffer,
                 "G-buffer sequence with `motion` (and `depth`, `id` for ema); without it the scene is static");
  app.add_option("--out", o.out, "Output sequence, e.g. phlm.####.exr")->required();
  app.add_option("--method", o.method, "phlm | taa | ema | fxaa")
      ->check(CLI::IsMember({"phlm", "taa", "ema", "fxaa"}));
  app.add_option("--layer", o.layer, "Layer to filter: rgb (R,G,B) or a layer name (ssao, shadow, direct, ...)");
  app.add_option("--frames", o.frames, "Frames A-B (default: every frame on disk)");
  app.add_option("--state-in", o.state_in, "Resume from a state file written by --state-out (same --method, --layer)");
  app.add_option("--state-out", o.state_out,
                 "Write the state (phlm: beta, P, feature; taa/ema: history) each frame (pattern with ####) or "
                 "after the last frame only (plain path)");
  app.add_flag("--debug-layers", o.debug, "Add debug.* layers (phlm: feature, alpha, reset, traceP)");
  app.add_option("--reset-frames", o.reset_frames, "Frames where every history is discarded, e.g. 10,20-22 "
                                                    "(also done where a header has temporal:cameraCut = 1)");
  app.add_option("--lambda", o.phlm.lambda, "phlm: RLS forgetting factor (seed 003 eq. 6-7)")
      ->check(CLI::Range(0.5f, 1.0f));
  app.add_option("--p-init", o.phlm.p_init, "phlm: P = p_init * I at reset (seed 003 section 6)")
      ->check(CLI::PositiveNumber);
  app.add_option("--feature-a", o.phlm.feature_a, "phlm: a of phi(v,l) = a l^2 + b v l^3 (section 5.1)");
  app.add_option("--feature-b", o.phlm.feature_b, "phlm: b of phi(v,l)");
  app.add_option("--trace-factor", o.phlm.trace_factor, "phlm: trace(P) <= factor * N * p_init (wind-up guard)")
      ->check(CLI::PositiveNumber);
  app.add_option("--taa-alpha", o.taa.alpha, "taa: weight of the current frame")->check(CLI::Range(0.0f, 1.0f));
  app.add_option("--ema-alpha", o.ema.alpha, "ema: history weight alpha of seed 003 eq. 1")
      ->check(CLI::Range(0.0f, 1.0f));
  app.add_option("--ema-depth-tolerance", o.ema.depth_tolerance, "ema: relative depth change that rejects history")
      ->check(CLI::PositiveNumber);
  app.add_option("--fxaa-subpix", o.fxaa.subpix, "fxaa: sub-pixel aliasing removal (fxaaQualitySubpix)");
  app.add_option("--fxaa-edge-threshold", o.fxaa.edge_threshold, "fxaa: fxaaQualityEdgeThreshold");
  app.add_option("--fxaa-edge-threshold-min", o.fxaa.edge_threshold_min, "fxaa: fxaaQualityEdgeThresholdMin");
  app.add_option("--compression", o.compression, "EXR compression of the outputs: none | zip | piz");
  return tool.run(argc, argv, [&] { return run(tool, o); });
}
