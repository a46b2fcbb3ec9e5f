// morph-120hz as a stage of the sequence runner (temporal/morph/morph_stage.h).
#include "temporal/morph/morph_stage.h"

#include "method_common.h"
#include "temporal/core/sequence.h"
#include "temporal/gpu/device.h"

#include <chrono>
#include <functional>
#include "temporal/morph/methods.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>

namespace temporal::morph {
namespace {

using namespace detail;

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

std::vector<std::string> layer_names(const std::vector<LayerNeed>& needs) {
  std::vector<std::string> names;
  for (const LayerNeed& n : needs) names.push_back(n.layer);
  return names;
}

std::string layer_list(const std::vector<std::string>& layers) {
  std::string s;
  for (std::size_t i = 0; i < layers.size(); ++i) s += (i == 0 ? "" : i + 1 == layers.size() ? " and " : ", ") + layers[i];
  return s;
}

// Frame-rate conversion with a method of the registry: `factor` outputs per input frame.
class FrameRateStage final : public FrameStage {
 public:
  FrameRateStage(const MorphStageOptions& options, const MethodEntry& entry)
      : options_(options), entry_(entry), layers_(layer_names(entry.layers(options.morph))),
        gbuffer_channels_(gbuffer_channels(layers_)) {
    inputs_.input_layers = layer_items(options.layer);
    for (const auto& l : layers_) inputs_.gbuffer_layers.push_back({l, true});
    inputs_.gbuffer_required = !layers_.empty();
    inputs_.gbuffer_purpose = "--method " + entry.info.name + " reads its " + layer_list(layers_);
    inputs_.lookahead = entry.lookahead;
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
      // A header is validated like an option: an infinite or absurd rate would give non-finite times (issue 26).
      if (!std::isfinite(fps) || fps < 1e-3 || fps > 1e4)
        return Error::input(f.input_path, "temporal:fps is " + std::to_string(fps) +
                                              ", not a rate in [0.001, 10000]: fix the header or pass --fps");
    }
    // Output frame numbers n * factor + k stay within the frame numbers every tool accepts (at most 99,999,999):
    // beyond, an int would wrap to a negative file name (issue 26 item 7).
    if ((long long)f.frame * options_.morph.factor + options_.morph.factor - 1 > 99'999'999LL)
      return Error::input(f.input_path, "frame " + std::to_string(f.frame) + " times --factor " +
                                            std::to_string(options_.morph.factor) +
                                            " is past frame 99,999,999, the largest output frame number; renumber "
                                            "the input frames from 0");
    if (!morpher_) {  // the viewing geometry and rate of the first frame set the eye-tracking limit
      MorphOptions mo = options_.morph;
      mo.pixels_per_degree = tracking_pixels_per_degree(options_.viewing, color->width());
      mo.fps = fps;
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
    // On the GPU the kernels' time (gpu/device.h: the uploads and downloads around them are not counted); on the
    // CPU the wall-clock time of the call.
    const gpu::ComputeTime time = gpu::compute_time(
        morpher_->gpu_context() ? dynamic_cast<const gpu::TimedKernel*>(morpher_->method()) : nullptr, total_ms_);
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
      o.timings_ms = {{"flow", timings_.flow_ms}, {"morph", timings_.morph_ms}, {"blur", timings_.blur_ms}};
      o.extra = {{"method", entry_.info.name},
                 // In frames of the output sequence: slot k of rendered frame n can be shown only once the
                 // method's lookahead has been rendered, latency_frames rendered frames = latency_frames * n
                 // display frames later (docs/conventions.md, "Latency").
                 {"latencyFrames", std::to_string(entry_.info.latency_frames.value_or(0) * n)},
                 {"sourceFrame", std::to_string(f.frame)},
                 {"slot", std::to_string(k)}};
      o.keep_input_metadata = false;
      // The rendered frame's work produces all its slots: each gets an equal share.
      gpu::record_device(o, morpher_->gpu_context(), {time.ms / n, time.clock});
      out.push_back(std::move(o));
    }
    return Status::ok();
  }

  std::string frame_summary() const override {
    char line[200];
    std::snprintf(line, sizeof line,
                  "%s, %d slots, %.2f ms (flow %.2f, morph %.2f, blur %.2f), gamma %.3g, %.2f pixels/degree",
                  entry_.info.name.c_str(), options_.morph.factor, total_ms_, timings_.flow_ms, timings_.morph_ms,
                  timings_.blur_ms, double(options_.morph.gamma),
                  double(morpher_ ? morpher_->options().pixels_per_degree : 0.0f));
    return line;
  }

 private:
  MorphStageOptions options_;
  const MethodEntry& entry_;
  std::vector<std::string> layers_;  // the G-buffer layers the method reads
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
  PerceiveStage(const HoldBlurOptions& hold, std::optional<SequencePattern> lag_reference, const LagSearchOptions& lag,
                std::function<Expected<Image>(const std::string&)> read_rgb)
      : hold_(hold), lag_reference_(std::move(lag_reference)), lag_(lag), read_rgb_(std::move(read_rgb)) {
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
    auto ref = read_rgb_(path);
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
  std::function<Expected<Image>(const std::string&)> read_rgb_;
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
  ViewingOptions& v = o.viewing;
  ParamList params = morph::params(o.morph);
  const ParamList stage = {
      Param::text("--layer", "Colour layer morphed: rgb (the bare R,G,B) or a layer with NAME.R,G,B (docs/conventions.md, "
                             "Layers); the outputs keep its channel names", &o.layer),
      // The range a header's temporal:fps must have too (MorphStage::run): frame / (fps n) stays finite.
      {.flag = "--fps", .help = "Input frame rate; 0 reads temporal:fps from the input header", .value = &o.fps,
       .min = 1e-3, .max = 1e4, .or_zero = true},
      {.flag = "--display",
       .help = "Display colour space whose gamma to use (e.g. gamma22_display, srgb_display); excludes --gamma",
       .value = &o.display},
      {.flag = "--ocio",
       .help = "OpenColorIO config for --display (default: $OCIO, else the built-in config)",
       .value = &o.ocio},
      // At least 0.01: the eye-tracking limit divides by it (speed = |motion| fps / ppd, grid_warp.cpp), and 1e-40
      // made that quotient infinite and the outputs NaN (issue 26 item 13).
      Param::real_or_zero("--ppd", "Pixels per degree of visual angle; 0 derives it from the screen geometry", &v.ppd,
                          0.01, 1e4),
      Param::real("--screen-width-m", "Screen width in metres (default: the paper's 22\" Samsung 2233RZ)",
                  &v.screen_width_m, 0.01, 100),
      Param::real("--distance-m", "Viewing distance in metres", &v.distance_m, 0.01, 100),
      Param::integer("--pixels-x", "Pixels across the screen (images are shown 1:1); 0: the image fills the screen width",
                     &v.pixels_x, 0, 1 << 20),
      Param::flag_off("--no-tracking-limit", "Disable the 70-90 deg/s eye-tracking damping (section 6)",
                      &v.tracking_limit),
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
  params.insert(params.end(), stage.begin(), stage.end());
  return params;
}

Expected<std::unique_ptr<FrameStage>> make_morph_stage(const MorphStageOptions& options, const MorphStageIO& io) {
  if (options.perceive) {
    if (layer_items(options.layer) != std::vector<std::string>{"rgb"})
      return Error::usage("--perceive reads the colour channels R, G, B: drop --layer " + options.layer);
    if (options.hold.window < 1) return Error::usage("--window must be at least 1");
    if (options.morph.device != kCpuDevice)  // an option that would do nothing is an error, not silence
      return Error::usage("--perceive runs on the CPU only: drop --device " + options.morph.device);
    std::optional<SequencePattern> lag_reference;
    if (!options.lag_reference.empty()) {
      auto p = SequencePattern::parse(options.lag_reference);
      if (!p) return p.error();
      lag_reference = *p;
      if (!io.read_rgb) return Error::usage("--lag-reference needs an image reader (MorphStageIO::read_rgb)");
    }
    return std::unique_ptr<FrameStage>(
        std::make_unique<PerceiveStage>(options.hold, lag_reference, options.lag, io.read_rgb));
  }
  if (!options.lag_reference.empty())  // an option that would do nothing is an error, not silence
    return Error::usage("--lag-reference measures the lag of a --perceive run: add --perceive, or drop it");
  if (Status s = check(options.morph); !s) return s.error();
  MorphStageOptions resolved = options;
  if (!options.display.empty()) {
    if (!io.display_gamma) return Error::usage("--display needs colour management (MorphStageIO::display_gamma)");
    auto gamma = io.display_gamma(options.display, options.ocio);
    if (!gamma) return gamma.error();
    resolved.morph.gamma = *gamma;
  }
  if (Status s = check(resolved.morph); !s) return s.error();
  return std::unique_ptr<FrameStage>(
      std::make_unique<FrameRateStage>(resolved, *find_entry(resolved.morph.method)));
}

}  // namespace temporal::morph
