// morph-120hz: turns a rendered sequence (e.g. 40 Hz) into a display-rate sequence (e.g. 120 Hz) with seed
// 004's grid morphing (didyk) or a baseline (repeat, blend, warp); or, with --perceive, simulates what an eye
// tracking the motion perceives on a hold-type display (seed 004 section 3). docs/morph-120hz.md.
#include "tool.h"

#include "temporal/core/color.h"
#include "temporal/core/exr.h"
#include "temporal/morph/hold_blur.h"
#include "temporal/morph/morph.h"
#include "temporal/core/sequence.h"

#include <chrono>
#include <cmath>
#include <deque>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

using namespace temporal;

namespace {

struct Options {
  std::string input, gbuffer, out, frames, method = "didyk", display, ocio, compression = "zip";
  int factor = 3;
  double fps = 0.0;
  float gamma = 2.2f;
  int grid = 8;
  float snap_threshold = 0.5f;
  bool no_snap = false;
  float blur_level = 2.0f;
  float distortion_low = 0.05f, distortion_high = 0.5f, min_blur = 0.0f;
  bool no_compensation = false;
  float ppd = 0.0f;
  float screen_width_m = 0.473f, distance_m = 0.6f;
  int pixels_x = 1680;
  bool no_tracking_limit = false;
  bool debug_layers = false;
  bool perceive = false;
  int window = 3;
};

// Replaces NaN/Inf by 0 in the named channels and returns how many there were (conventions: counted,
// reported, never propagated).
std::size_t sanitize(Image& image, const std::vector<std::string>& channels) {
  std::size_t bad = 0;
  for (const auto& ch : channels) {
    float* p = image.plane(ch);
    if (!p) continue;
    for (std::size_t i = 0; i < image.pixel_count(); ++i)
      if (!std::isfinite(p[i])) {
        p[i] = 0.0f;
        ++bad;
      }
  }
  return bad;
}

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

Expected<Image> read_checked(tool::Tool& tool, const std::string& path, const std::vector<std::string>& layers,
                             const std::vector<std::string>& channels) {
  auto img = read_exr(path, ExrSelection{layers});
  if (!img) {
    Error e = img.error();
    if (e.file.empty()) e.file = path;
    return e;
  }
  const std::size_t bad = sanitize(*img, channels);
  if (bad > 0) tool.print_warning(path, std::to_string(bad) + " non-finite values (NaN/Inf) replaced by 0");
  return img;
}

Status run_perceive(tool::Tool& tool, const Options& o, const SequencePattern& in, const SequencePattern& gb,
                    const SequencePattern& out, const std::vector<int>& frames, const ExrWriteOptions& wopt) {
  const std::vector<std::string> rgb = {"R", "G", "B"};
  HoldBlurOptions ho;
  ho.window = o.window;
  std::deque<std::pair<int, Image>> cache;
  tool::Progress progress(tool.name(), int(frames.size()));
  for (const int f : frames) {
    // Window of displayed frames f .. f+W-1: read from disk even past the selected range (the eye keeps
    // integrating), stopping at the first frame that does not exist (the end of the sequence).
    while (!cache.empty() && cache.front().first < f) cache.pop_front();
    for (int j = cache.empty() ? f : cache.back().first + 1; j < f + o.window; ++j) {
      if (j != f && !std::filesystem::exists(in.path(j))) break;
      auto img = read_checked(tool, in.path(j), {"rgb"}, rgb);
      if (!img) return img.error();
      cache.emplace_back(j, std::move(*img));
    }
    auto g = read_checked(tool, gb.path(f), {"motion"}, {"motion.X", "motion.Y"});
    if (!g) return g.error();
    if (g->width() != cache.front().second.width() || g->height() != cache.front().second.height())
      return Error::input(gb.path(f), "the G-buffer's size differs from the input's; render both at the same size");
    std::vector<const Image*> window;
    for (auto& [n, img] : cache) window.push_back(&img);
    const auto t0 = std::chrono::steady_clock::now();
    auto p = perceive_hold(window, rgb, g->plane("motion.X"), g->plane("motion.Y"), ho);
    if (!p) {
      Error e = p.error();
      e.file = in.path(f);
      return e;
    }
    FrameMetadata& md = p->metadata();
    md.tool = tool.signature();
    md.parameters = tool.command_line();
    md.compute_ms = ms_since(t0);
    md.timings_ms.clear();
    md.frame = f;
    md.extra["perceivedWindow"] = std::to_string(window.size());
    if (Status s = write_exr(out.path(f), *p, wopt); !s) return s;
    progress.step(f);
  }
  return Status::ok();
}

Status run(tool::Tool& tool, const Options& o) {
  auto in = SequencePattern::parse(o.input);
  if (!in) return in.error();
  auto out = SequencePattern::parse(o.out);
  if (!out) return out.error();
  if (!out->has_placeholder())
    return Error::usage("--out '" + o.out + "' has no frame placeholder: write e.g. out/color.####.exr");
  std::optional<FrameRange> range;
  if (!o.frames.empty()) {
    auto r = FrameRange::parse(o.frames);
    if (!r) return r.error();
    range = *r;
  }
  auto frames = resolve_frames(*in, range);
  if (!frames) return frames.error();
  auto comp = parse_compression(o.compression);
  if (!comp) return comp.error();
  ExrWriteOptions wopt;
  wopt.compression = *comp;
  auto method = parse_morph_method(o.method);
  if (!method) return method.error();
  const bool needs_gbuffer = o.perceive || *method == MorphMethod::Didyk || *method == MorphMethod::Warp;
  std::optional<SequencePattern> gb;
  if (needs_gbuffer) {
    if (o.gbuffer.empty())
      return Error::usage(o.perceive ? "--perceive needs --gbuffer (the display-rate motion)"
                                     : "--method " + o.method + " needs --gbuffer G.####.exr (motion and depth)");
    auto g = SequencePattern::parse(o.gbuffer);
    if (!g) return g.error();
    gb = *g;
  }
  if (o.perceive) return run_perceive(tool, o, *in, *gb, *out, *frames, wopt);
  if (o.factor < 2) return Error::usage("--factor must be at least 2 (got " + std::to_string(o.factor) + ")");

  MorphOptions mo;
  mo.method = *method;
  mo.factor = o.factor;
  mo.gamma = o.gamma;
  if (!o.display.empty()) {
    auto cfg = ColorConfig::load(o.ocio);
    if (!cfg) return cfg.error();
    auto g = cfg->display_gamma(o.display);
    if (!g) return g.error();
    mo.gamma = *g;
    tool.log("display '" + o.display + "': gamma " + std::to_string(mo.gamma));
  }
  mo.grid.cell = o.grid;
  mo.grid.snap = !o.no_snap;
  mo.grid.snap_threshold = o.snap_threshold;
  mo.blur_level = o.blur_level;
  mo.distortion_low = o.distortion_low;
  mo.distortion_high = o.distortion_high;
  mo.min_blur = o.min_blur;
  mo.compensate = !o.no_compensation;
  mo.debug_layers = o.debug_layers;

  const std::vector<std::string> rgb = {"R", "G", "B"};
  Morpher morpher(mo);
  std::vector<Image> slots;
  std::optional<std::pair<int, Image>> next_cache;
  tool::Progress progress(tool.name(), int(frames->size()));
  for (std::size_t fi = 0; fi < frames->size(); ++fi) {
    const int n = (*frames)[fi];
    const std::string cpath = in->path(n);
    Image color;
    if (next_cache && next_cache->first == n) {
      color = std::move(next_cache->second);
      next_cache.reset();
    } else {
      auto c = read_checked(tool, cpath, {"rgb"}, rgb);
      if (!c) return c.error();
      color = std::move(*c);
    }
    double fps = o.fps;
    if (fps <= 0.0) {
      if (!color.metadata().fps)
        return Error::input(cpath, "no temporal:fps in the header: pass --fps (the rate it was rendered at)");
      fps = *color.metadata().fps;
    }
    std::optional<Image> gbuf;
    if (gb) {
      auto g = read_checked(tool, gb->path(n), {"motion", "depth"}, {"motion.X", "motion.Y", "depth.Z"});
      if (!g) return g.error();
      gbuf = std::move(*g);
    }
    const Image* next = nullptr;
    if (mo.method == MorphMethod::Blend && fi + 1 < frames->size()) {
      auto c = read_checked(tool, in->path((*frames)[fi + 1]), {"rgb"}, rgb);
      if (!c) return c.error();
      next_cache.emplace((*frames)[fi + 1], std::move(*c));
      next = &next_cache->second;
    }
    // Eye-tracking limit: pixels per degree from --ppd or from the viewing geometry.
    if (o.no_tracking_limit) {
      mo.grid.pixels_per_degree = 0.0f;
    } else {
      mo.grid.pixels_per_degree =
          o.ppd > 0.0f ? o.ppd
                       : pixels_per_degree(o.screen_width_m, o.distance_m, o.pixels_x > 0 ? o.pixels_x : color.width());
    }
    mo.grid.fps = fps;
    if (fi == 0) {
      morpher = Morpher(mo);
      tool.log("method " + o.method + ", factor " + std::to_string(o.factor) + ", gamma " + std::to_string(mo.gamma) +
               ", " + std::to_string(mo.grid.pixels_per_degree) + " pixels/degree");
    }
    MorphTimings timings;
    const auto t0 = std::chrono::steady_clock::now();
    Status s = morpher.process(color, gbuf ? &*gbuf : nullptr, next, slots, &timings);
    const double total_ms = ms_since(t0);
    if (!s) {
      Error e = s.error();
      if (e.file.empty()) e.file = gbuf && e.message.find("G-buffer") != std::string::npos ? gb->path(n) : cpath;
      return e;
    }
    for (int k = 0; k < o.factor; ++k) {
      Image& img = slots[std::size_t(k)];
      FrameMetadata md = color.metadata();
      const int frame = n * o.factor + k;
      md.frame = frame;
      md.fps = fps * o.factor;
      md.time = double(frame) / (fps * o.factor);
      md.tool = tool.signature();
      md.parameters = tool.command_line();
      // The work for one rendered frame produces all its slots; each slot is charged an equal share.
      md.compute_ms = total_ms / o.factor;
      md.timings_ms.clear();  // the input's pass timings (render-gbuffer's) do not describe this stage
      md.timings_ms["flow"] = timings.flow_ms;
      md.timings_ms["morph"] = timings.morph_ms;
      md.timings_ms["blur"] = timings.blur_ms;
      md.extra["method"] = morph_method_name(mo.method);
      md.extra["latencyFrames"] = mo.method == MorphMethod::Blend ? "1" : "0";
      md.extra["sourceFrame"] = std::to_string(n);
      md.extra["slot"] = std::to_string(k);
      if (k > 0) {
        // The rendered frame's camera and jitter do not describe an extrapolated frame.
        md.world_to_camera.reset();
        md.world_to_ndc.reset();
        md.jitter.reset();
        md.camera_cut.reset();
      }
      img.metadata() = md;
      if (Status ws = write_exr(out->path(frame), img, wopt); !ws) return ws;
    }
    progress.step(n);
  }
  return Status::ok();
}

}  // namespace

int main(int argc, char** argv) {
  tool::Tool tool("morph-120hz",
                  "Temporal upsampling of rendered frames for high-refresh-rate displays (Didyk et al. 2010): "
                  "each input frame n becomes output frames n*factor+k, k = 0..factor-1, at time "
                  "(n*factor+k)/(fps*factor). With --perceive: simulate hold-type blur under smooth pursuit.");
  Options o;
  CLI::App& app = tool.app();
  app.add_option("--input", o.input, "Colour sequence (R,G,B scene-linear), e.g. render/color.####.exr")->required();
  app.add_option("--gbuffer", o.gbuffer, "G-buffer sequence with motion and depth (didyk, warp, --perceive)");
  app.add_option("--out", o.out, "Output sequence pattern, e.g. out/color.####.exr")->required();
  app.add_option("--frames", o.frames, "Input frames A-B (default: every frame on disk)");
  app.add_option("--method", o.method, "didyk | repeat | blend | warp")
      ->check(CLI::IsMember({"didyk", "repeat", "blend", "warp"}));
  app.add_option("--factor", o.factor, "Output frames per input frame (>= 2; 40 Hz -> 120 Hz: 3)");
  app.add_option("--fps", o.fps, "Input frame rate; 0 reads temporal:fps from the header");
  auto* gamma = app.add_option("--gamma", o.gamma, "Display gamma g of the compensation H' (displayed light = value^g)");
  app.add_option("--display", o.display, "Display colour space whose gamma to use (e.g. gamma22_display, srgb_display)")
      ->excludes(gamma);
  app.add_option("--ocio", o.ocio, "OpenColorIO config for --display (default: $OCIO, else the built-in config)");
  app.add_option("--grid", o.grid, "Grid cell size in pixels (power of two, 2..32)");
  app.add_option("--snap-threshold", o.snap_threshold, "Smallest motion difference (px) a vertex snaps to");
  app.add_flag("--no-snap", o.no_snap, "Keep the grid regular (no snapping to motion discontinuities)");
  app.add_option("--blur-level", o.blur_level, "Blur pyramid level read for the low-pass layer (fractional allowed)");
  app.add_option("--distortion-low", o.distortion_low, "Cell distortion (fraction of a cell) where blur starts");
  app.add_option("--distortion-high", o.distortion_high, "Cell distortion where the in-between frame is fully blurred");
  app.add_option("--min-blur", o.min_blur, "Blur strength floor of the in-between frames, 0..1 (1: blur everywhere)")
      ->check(CLI::Range(0.0, 1.0));
  app.add_flag("--no-compensation", o.no_compensation, "Do not add compensating high frequencies to the rendered frame");
  auto* ppd = app.add_option("--ppd", o.ppd, "Pixels per degree of visual angle; 0 derives it from the screen geometry");
  app.add_option("--screen-width-m", o.screen_width_m, "Screen width in metres (defaults: the paper's 22\" Samsung 2233RZ)")
      ->excludes(ppd);
  app.add_option("--distance-m", o.distance_m, "Viewing distance in metres")->excludes(ppd);
  app.add_option("--pixels-x", o.pixels_x,
                 "Pixels across the screen (images are shown 1:1); 0: the image fills the screen width")->excludes(ppd);
  app.add_flag("--no-tracking-limit", o.no_tracking_limit, "Disable the 70-90 deg/s eye-tracking damping");
  app.add_flag("--debug-layers", o.debug_layers,
               "Add debug.grid, debug.distortion, debug.blur, debug.H, debug.Hprime (didyk)");
  app.add_flag("--perceive", o.perceive,
               "Instead of upsampling: write the image perceived on a hold-type display under smooth pursuit "
               "(--input at its display rate, --gbuffer its display-rate motion)");
  app.add_option("--window", o.window, "--perceive: displayed frames integrated by the eye")->check(CLI::PositiveNumber);
  app.add_option("--compression", o.compression, "EXR compression: none | zip | piz | dwaa");
  return tool.run(argc, argv, [&] { return run(tool, o); });
}
