// morph-120hz as a stage of the sequence runner (temporal/morph/morph_stage.h).
#include "temporal/morph/morph_stage.h"

#include "method_common.h"
#include "temporal/core/color.h"
#include "temporal/core/exr.h"
#include "temporal/core/sequence.h"
#include "temporal/morph/methods.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>

namespace temporal {
namespace {

using namespace morph_detail;

// NaN/Inf policy of the morph stage (conventions: counted, reported, never propagated): the runner counts and
// reports them; here they become 0. Returns `image` itself when its `channels` are finite (the common case, no
// copy), else a copy in `scratch` with the non-finite values replaced.
const Image* finite_copy(const Image* image, const std::vector<std::string>& channels, Image& scratch) {
  if (!image) return nullptr;
  bool finite = true;
  for (const auto& ch : channels)
    if (const float* p = image->plane(ch)) finite = finite && count_non_finite({p, image->pixel_count()}) == 0;
  if (finite) return image;
  scratch = *image;
  for (const auto& ch : channels) {
    float* p = scratch.plane(ch);
    if (!p) continue;
    for (std::size_t i = 0; i < scratch.pixel_count(); ++i) p[i] = std::isfinite(p[i]) ? p[i] : 0.0f;
  }
  return &scratch;
}

const std::vector<std::string> kColor = {"R", "G", "B"};

// A copy of `image` with channel from[k] called to[k] (the other channels as they are): the morph methods read
// and write R, G, B, so another --layer is morphed under those names and written back under its own.
Image renamed(const Image& image, const std::vector<std::string>& from, const std::vector<std::string>& to) {
  Image out(image.width(), image.height());
  out.metadata() = image.metadata();
  for (std::size_t i = 0; i < image.channel_count(); ++i) {
    const std::string& name = image.channel_name(i);
    const auto k = std::find(from.begin(), from.end(), name);
    const std::string& target = k == from.end() ? name : to[std::size_t(k - from.begin())];
    if (const float* src = image.plane(name))
      std::copy(src, src + image.pixel_count(), out.add_channel(target));
    else if (const std::uint32_t* usrc = image.uint_plane(name))
      std::copy(usrc, usrc + image.pixel_count(), out.add_uint_channel(target));
  }
  return out;
}

std::vector<std::string> gbuffer_channels(const std::vector<std::string>& layers) {
  std::vector<std::string> channels;
  for (const auto& l : layers)
    for (auto& c : morph_gbuffer_channels(l)) channels.push_back(std::move(c));
  return channels;
}

std::string layer_list(const std::vector<std::string>& layers) {
  std::string s;
  for (std::size_t i = 0; i < layers.size(); ++i) s += (i == 0 ? "" : i + 1 == layers.size() ? " and " : ", ") + layers[i];
  return s;
}

// Frame-rate conversion with a method of the registry: `factor` outputs per input frame.
class UpsampleStage final : public FrameStage {
 public:
  UpsampleStage(const MorphStageOptions& options, const MorphMethodInfo& info)
      : options_(options), info_(info), gbuffer_channels_(gbuffer_channels(info.gbuffer_layers)) {
    inputs_.input_layers = layer_items(options.layer);
    for (const auto& l : info.gbuffer_layers) inputs_.gbuffer_layers.push_back({l, true});
    inputs_.gbuffer_required = !info.gbuffer_layers.empty();
    inputs_.gbuffer_purpose = "--method " + info.name + " reads its " + layer_list(info.gbuffer_layers);
    inputs_.lookahead = info.lookahead;
    inputs_.lookahead_past_range = false;  // the last selected frame repeats, as at the end of the sequence
    inputs_.outputs_per_frame = options.morph.factor;
  }

  const StageInputs& inputs() const override { return inputs_; }

  Status process(const StageFrame& f, std::vector<StageOutput>& out) override {
    auto layer = select_layers(*f.input, options_.layer, f.input_path);
    if (!layer) return layer.error();
    if (layer->size() != 3)
      return Error::usage("--layer " + options_.layer + " has " + std::to_string(layer->size()) +
                          " channels; the morph methods take 3 (a colour layer: rgb, direct, ...)");
    const bool bare = *layer == kColor;  // rgb: no copies
    const Image* input = f.input;
    const Image* following = f.next.empty() ? nullptr : f.next.front();
    if (!bare) {
      layer_input_ = renamed(*f.input, *layer, kColor);
      input = &layer_input_;
      if (following) {
        layer_next_ = renamed(*following, *layer, kColor);
        following = &layer_next_;
      }
    }
    const Image* color = finite_copy(input, kColor, color_);
    const Image* gbuffer = finite_copy(f.gbuffer, gbuffer_channels_, gbuffer_);
    const Image* next = following ? finite_copy(following, kColor, next_) : nullptr;
    double fps = options_.fps;
    if (fps <= 0.0) {
      if (!color->metadata().fps)
        return Error::input(f.input_path, "no temporal:fps in the header: pass --fps (the rate it was rendered at)");
      fps = *color->metadata().fps;
    }
    if (!morpher_) {  // the viewing geometry and rate of the first frame set the eye-tracking limit
      MorphOptions mo = options_.morph;
      mo.grid.pixels_per_degree = tracking_pixels_per_degree(options_.viewing, color->width());
      mo.grid.fps = fps;
      morpher_.emplace(mo);
    }
    const auto t0 = std::chrono::steady_clock::now();
    Status s = morpher_->process(*color, gbuffer, next, slots_, &timings_);
    total_ms_ = ms_since(t0);
    if (!s) {
      Error e = s.error();
      if (e.file.empty()) e.file = gbuffer && e.message.find("G-buffer") != std::string::npos ? f.gbuffer_path : f.input_path;
      return e;
    }
    const int n = options_.morph.factor;
    for (int k = 0; k < n; ++k) {
      const int frame = f.frame * n + k;
      FrameMetadata md = f.input->metadata();
      md.fps = fps * n;
      md.time = double(frame) / (fps * n);
      if (k > 0) {  // the rendered frame's camera and jitter do not describe an extrapolated frame
        md.world_to_camera.reset();
        md.world_to_ndc.reset();
        md.jitter.reset();
        md.camera_cut.reset();
      }
      Image* img = &slots_[std::size_t(k)];
      if (!bare) {  // the slots stay the morpher's (it reuses them next frame)
        layer_slots_.resize(slots_.size());
        layer_slots_[std::size_t(k)] = renamed(*img, kColor, *layer);
        img = &layer_slots_[std::size_t(k)];
      }
      img->metadata() = std::move(md);
      StageOutput o;
      o.frame = frame;
      o.image = img;
      o.compute_ms = total_ms_ / n;  // the rendered frame's work produces all its slots: each gets an equal share
      o.timings_ms = {{"flow", timings_.flow_ms}, {"morph", timings_.morph_ms}, {"blur", timings_.blur_ms}};
      o.extra = {{"method", info_.name},
                 // In frames of the output sequence: slot k of rendered frame n can be shown only once the
                 // method's lookahead has been rendered, latency_frames rendered frames = latency_frames * n
                 // display frames later (docs/conventions.md, "Latency").
                 {"latencyFrames", std::to_string(info_.latency_frames * n)},
                 {"sourceFrame", std::to_string(f.frame)},
                 {"slot", std::to_string(k)}};
      o.keep_input_metadata = false;
      out.push_back(std::move(o));
    }
    return Status::ok();
  }

  std::string frame_summary() const override {
    char line[200];
    std::snprintf(line, sizeof line,
                  "%s, %d slots, %.2f ms (flow %.2f, morph %.2f, blur %.2f), gamma %.3g, %.2f pixels/degree",
                  info_.name.c_str(), options_.morph.factor, total_ms_, timings_.flow_ms, timings_.morph_ms,
                  timings_.blur_ms, double(options_.morph.gamma),
                  double(morpher_ ? morpher_->options().grid.pixels_per_degree : 0.0f));
    return line;
  }

 private:
  MorphStageOptions options_;
  const MorphMethodInfo& info_;
  std::vector<std::string> gbuffer_channels_;
  StageInputs inputs_;
  std::optional<Morpher> morpher_;
  std::vector<Image> slots_;
  Image color_, gbuffer_, next_;  // finite copies (only of frames with NaN/Inf)
  Image layer_input_, layer_next_;  // a --layer other than rgb under the names R, G, B
  std::vector<Image> layer_slots_;  // the slots under the layer's names
  MorphTimings timings_;
  double total_ms_ = 0.0;
};

// --perceive: the image an eye tracking the motion perceives on a hold-type display (hold_blur.h), one output per
// input frame, integrating the window of displayed frames that starts at it.
class PerceiveStage final : public FrameStage {
 public:
  PerceiveStage(const HoldBlurOptions& hold, std::optional<SequencePattern> lag_reference, const LagSearchOptions& lag)
      : hold_(hold), lag_reference_(std::move(lag_reference)), lag_(lag) {
    inputs_.input_layers = {"rgb"};
    inputs_.gbuffer_layers = {{"motion", true}};
    inputs_.gbuffer_required = true;
    inputs_.gbuffer_purpose = "--perceive reads the display-rate motion";
    inputs_.lookahead = hold.window - 1;  // read past the selected frames while files exist: the eye keeps integrating
    scratch_.resize(std::size_t(hold.window));
  }

  const StageInputs& inputs() const override { return inputs_; }

  Status process(const StageFrame& f, std::vector<StageOutput>& out) override {
    std::vector<const Image*> window = {finite_copy(f.input, kColor, scratch_[0])};
    for (std::size_t i = 0; i < f.next.size() && i + 1 < scratch_.size(); ++i)
      window.push_back(finite_copy(f.next[i], kColor, scratch_[i + 1]));
    const Image* g = finite_copy(f.gbuffer, {"motion.X", "motion.Y"}, gbuffer_);
    const auto t0 = std::chrono::steady_clock::now();
    auto p = perceive_hold(window, kColor, g->plane("motion.X"), g->plane("motion.Y"), hold_);
    if (!p) return p.error();
    result_ = std::move(*p);
    StageOutput o;
    o.frame = f.frame;
    o.image = &result_;
    o.compute_ms = ms_since(t0);
    o.extra = {{"perceivedWindow", std::to_string(window.size())}};
    if (lag_reference_)
      if (Status s = align(f, *g, o); !s) return s;
    out.push_back(std::move(o));
    return Status::ok();
  }

 private:
  // The lag apart from the blur. The declared latency L (temporal:latencyFrames) is known exactly and is added,
  // not searched; the search finds the lag of the content itself (repeat's held frames, an extrapolation that
  // falls short) against the native perceived frame of the same instant, t. Aligning against frame t + L
  // instead would ask one shift to explain L frames of native motion, which it cannot where the motion is not a
  // translation (rotation, disocclusions over L frames), and that residual would be charged as blur.
  Status align(const StageFrame& f, const Image& gbuffer, StageOutput& o) {
    int latency = 0;
    const auto& extra = f.input->metadata().extra;
    if (const auto it = extra.find("latencyFrames"); it != extra.end()) {
      char* end = nullptr;
      const long v = std::strtol(it->second.c_str(), &end, 10);
      if (end == it->second.c_str() || *end != '\0' || v < 0 || v > 100000)
        return Error::input(f.input_path, "temporal:latencyFrames is '" + it->second + "', not a whole number >= 0");
      latency = int(v);
    }
    const std::string path = lag_reference_->path(f.frame);
    auto ref = read_exr(path, ExrSelection{{"rgb"}});
    if (!ref)
      return Error::input(path, "no perceived reference image for frame " + std::to_string(f.frame) +
                                    ": run --perceive on the native sequence through frame " + std::to_string(f.frame) +
                                    " (" + ref.error().message + ")");
    const auto t0 = std::chrono::steady_clock::now();
    auto a = align_lag(result_, *ref, kColor, gbuffer.plane("motion.X"), gbuffer.plane("motion.Y"), lag_);
    if (!a) {
      Error e = a.error();
      if (e.file.empty()) e.file = path;
      return e;
    }
    for (const auto& c : kColor) {
      const float* src = a->aligned.plane(c);
      float* dst = result_.add_channel("aligned." + c);
      std::copy(src, src + result_.pixel_count(), dst);
    }
    const double lag = a->lag_frames + double(latency);
    char text[64];
    std::snprintf(text, sizeof text, "%.5f", a->lag_frames);
    o.extra["lagContentFrames"] = text;
    std::snprintf(text, sizeof text, "%.5f", lag);
    o.extra["lagFrames"] = text;
    o.extra["lagReferenceFrame"] = std::to_string(f.frame);
    if (const auto fps = f.input->metadata().fps; fps && *fps > 0.0) {
      std::snprintf(text, sizeof text, "%.4f", lag * 1000.0 / *fps);
      o.extra["lagMs"] = text;
    }
    o.timings_ms["lag"] = ms_since(t0);
    return Status::ok();
  }

  HoldBlurOptions hold_;
  std::optional<SequencePattern> lag_reference_;
  LagSearchOptions lag_;
  StageInputs inputs_;
  std::vector<Image> scratch_;  // finite copies of the window (only of frames with NaN/Inf)
  Image gbuffer_, result_;
};

}  // namespace

float tracking_pixels_per_degree(const ViewingOptions& v, int image_width) {
  if (!v.tracking_limit) return 0.0f;
  if (v.ppd > 0.0f) return v.ppd;
  return pixels_per_degree(v.screen_width_m, v.distance_m, v.pixels_x > 0 ? v.pixels_x : image_width);
}

ParamList morph_stage_params(MorphStageOptions& o) {
  std::vector<std::string> names;
  for (const auto& m : morph_methods()) names.push_back(m.name);
  ParamList params = {
      Param::choice("--method", "Method (the registry's: morph-120hz --list-methods)", &o.morph.method, names),
      Param::integer("--factor", "Output frames per input frame (40 Hz -> 120 Hz: 3)", &o.morph.factor, 2, 32),
      Param::text("--layer", "Colour layer morphed: rgb (the bare R,G,B) or a layer with NAME.R,G,B (docs/conventions.md, "
                             "Layers); the outputs keep its channel names", &o.layer),
      {.flag = "--fps", .help = "Input frame rate; 0 reads temporal:fps from the input header", .value = &o.fps,
       .min = 0.0, .max = 1e4},
      Param::flag_on("--debug-layers", "Add debug.grid, debug.distortion, debug.blur, debug.H, debug.Hprime (didyk)",
                     &o.morph.debug_layers),
      Param::flag_on("--perceive",
                     "Instead of upsampling: write the image perceived on a hold-type display under smooth pursuit "
                     "(--input at its display rate, --gbuffer its display-rate motion)",
                     &o.perceive),
      Param::integer("--window", "--perceive: displayed frames integrated by the eye", &o.hold.window, 1, 64),
      {.flag = "--lag-reference",
       .help = "--perceive: perceived images of the native stream (P.####.exr); adds layer aligned.R,G,B (the best "
               "shift along the motion against the native frame t) and temporal:lagFrames, lagMs (plus the declared "
               "temporal:latencyFrames)",
       .value = &o.lag_reference},
      Param::real("--max-lag", "--perceive --lag-reference: largest lag searched, display frames", &o.lag.max_lag_frames,
                  0, 64),
  };
  for (const auto& m : morph_methods()) {
    if (!m.params) continue;
    for (auto& p : m.params(o)) {
      // --help lists a method's parameters under its name; one several methods read, under all of theirs.
      const auto listed = std::find_if(params.begin(), params.end(), [&](const Param& q) { return q.flag == p.flag; });
      if (listed == params.end()) {
        p.group = m.name;
        params.push_back(std::move(p));
      } else if (!listed->group.empty()) {
        listed->group += ", " + m.name;
      }
    }
  }
  return params;
}

Expected<std::unique_ptr<FrameStage>> make_morph_stage(const MorphStageOptions& options) {
  if (options.perceive) {
    if (layer_items(options.layer) != std::vector<std::string>{"rgb"})
      return Error::usage("--perceive reads the colour channels R, G, B: drop --layer " + options.layer);
    if (options.hold.window < 1) return Error::usage("--window must be at least 1");
    std::optional<SequencePattern> lag_reference;
    if (!options.lag_reference.empty()) {
      auto p = SequencePattern::parse(options.lag_reference);
      if (!p) return p.error();
      lag_reference = *p;
    }
    return std::unique_ptr<FrameStage>(std::make_unique<PerceiveStage>(options.hold, lag_reference, options.lag));
  }
  if (!options.lag_reference.empty())  // an option that would do nothing is an error, not silence
    return Error::usage("--lag-reference measures the lag of a --perceive run: add --perceive, or drop it");
  auto info = find_morph_method(options.morph.method);
  if (!info) return info.error();
  MorphStageOptions resolved = options;
  if (!options.display.empty()) {
    auto config = ColorConfig::load(options.ocio);
    if (!config) return config.error();
    auto gamma = config->display_gamma(options.display);
    if (!gamma) return gamma.error();
    resolved.morph.gamma = *gamma;
  }
  if (Status s = check_morph_options(resolved.morph); !s) return s.error();
  return std::unique_ptr<FrameStage>(std::make_unique<UpsampleStage>(resolved, **info));
}

}  // namespace temporal
