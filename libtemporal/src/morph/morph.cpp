// Seed 004 (Didyk et al. 2010): the compensation formulas of section 5.1 and Morpher, which runs any method of
// the registry (temporal/morph/methods.h) on one rendered frame: it checks the options and the inputs against
// what the method reads, sizes the output slots, and hands them to the method's state. The methods live in
// their own files (didyk.cpp, repeat.cpp, blend.cpp, warp.cpp); docs/morph-120hz.md lists the choices the paper
// leaves open.
#include "temporal/morph/morph.h"

#include "temporal/gpu/device.h"
#include "temporal/morph/methods.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace temporal::morph {

float compensated_high_frequency(float high, float low, float frames, float gamma) {
  // Section 5.1: N (H + L)^g = (L + H')^g + (N - 1) L^g.
  const double v = double(frames) * std::pow(double(high + low), double(gamma)) -
                   (double(frames) - 1.0) * std::pow(double(low), double(gamma));
  return float(std::pow(std::max(v, 0.0), 1.0 / double(gamma)) - double(low));
}

// The scalar reference of the per-pixel loop of didyk (didyk.cpp, which works in linear light).
CompensatedValue compensate_value(float original, float low, float blurred, float gamma) {
  if (!(original >= 0.0f && original <= 1.0f)) return {original, original};
  // Rule 1: an original darker than its low-pass keeps the original in every frame (the blurred frames
  // would otherwise need negative light to compensate the brightening of dark pixels).
  if (original < low) return {original, original};
  if (!(blurred > 0.0f)) return {original, low};
  const double og = std::pow(double(original), double(gamma)), lg = std::pow(double(low), double(gamma));
  const double top_g = (1.0 + blurred) * og - blurred * lg;
  if (top_g <= 1.0) return {float(std::pow(top_g, 1.0 / gamma)), low};
  // Rule 2: the enhanced original would exceed the display's range: show 1 and move the excess energy into
  // the low-frequency layer of the in-between frames: 1 + B low'^g = (1 + B) original^g.
  return {1.0f, float(std::pow(((1.0 + blurred) * og - 1.0) / blurred, 1.0 / gamma))};
}

Morpher::Morpher(MorphOptions options) : options_(std::move(options)) {}

Status Morpher::check(const Image& color, const Image* gbuffer, const Image* next) const {
  if (Status s = morph::check(options_); !s) return s;
  for (const char* ch : {"R", "G", "B"})
    if (!color.plane(ch))
      return Error::input({}, std::string("the colour input has no float channel '") + ch +
                                  "': pass an image with R, G, B (render-gbuffer --outputs color)");
  if (color.empty()) return Error::input({}, "the colour input is empty");
  std::vector<std::string> layers;
  for (const LayerNeed& need : entry_->layers(options_)) layers.push_back(need.layer);
  if (!layers.empty()) {
    std::string list;
    for (std::size_t i = 0; i < layers.size(); ++i) list += (i == 0 ? "" : i + 1 == layers.size() ? " and " : ", ") + layers[i];
    if (!gbuffer) return Error::input({}, "this method needs the G-buffer (--gbuffer) with " + list);
    for (const auto& layer : layers) {
      std::string channels;
      bool ok = true;
      for (const auto& ch : morph_gbuffer_channels(layer)) {
        ok = ok && gbuffer->plane(ch) != nullptr;
        channels += (channels.empty() ? "" : ", ") + ch;
      }
      if (!ok)
        return Error::input({}, "the G-buffer has no '" + layer + "' layer (" + channels +
                                    "): render it with render-gbuffer --outputs gbuffer");
    }
    if (gbuffer->width() != color.width() || gbuffer->height() != color.height())
      return Error::input({}, "the G-buffer is " + std::to_string(gbuffer->width()) + "x" + std::to_string(gbuffer->height()) +
                                  " but the colour is " + std::to_string(color.width()) + "x" +
                                  std::to_string(color.height()) + ": render both at the same size");
  }
  if (next && entry_->lookahead > 0) {
    for (const char* ch : {"R", "G", "B"})
      if (!next->plane(ch)) return Error::input({}, std::string("the next colour frame has no channel '") + ch + "'");
    if (next->width() != color.width() || next->height() != color.height())
      return Error::input({}, "the next colour frame's size differs from this frame's");
  }
  return Status::ok();
}

Morpher::~Morpher() = default;
Morpher::Morpher(Morpher&&) noexcept = default;
Morpher& Morpher::operator=(Morpher&&) noexcept = default;

Status check(const MorphOptions& options) {
  if (Status s = check_method_name(registry(), options.method); !s) return s;
  if (Status s = check_method_device(*find_entry(options.method), options.device); !s) return s;
  if (options.factor < 2)
    return Error::usage("--factor must be at least 2 (got " + std::to_string(options.factor) + ")");
  if (!(options.gamma > 0.0f)) return Error::usage("--gamma must be positive");
  return check_method_options(registry(), options.per_method);
}

Status Morpher::process(const Image& color, const Image* gbuffer, const Image* next, std::vector<Image>& out,
                        MorphTimings* timings) {
  if (!method_) {
    if (Status s = morph::check(options_); !s) return s;
    entry_ = find_entry(options_.method);
    // The implementation on --device (check() made sure the method has one there).
    const auto* implementation = find_implementation(*entry_, options_.device);
    if (!implementation) return check_method_device(*entry_, options_.device);
    // By the device, not the factory's kind: an adapter with the CPU signature registered for the GPU (one that
    // makes its own context) still runs there, and the headers name the device's context.
    if (options_.device == kGpuDevice && !gpu_) {
      auto context = gpu::context_for_device(options_.device);
      if (!context) return context.error();
      gpu_ = std::move(*context);
    }
    auto made = implementation->make(gpu_, options_);
    if (!made) return made.error();
    method_ = std::move(*made);
  }
  if (Status s = check(color, gbuffer, next); !s) return s;
  const int w = color.width(), h = color.height();
  out.resize(std::size_t(options_.factor));
  for (auto& o : out) {
    if (o.width() != w || o.height() != h) o = Image(w, h);
    for (const char* ch : {"R", "G", "B"}) o.add_channel(ch);
    if (options_.debug_layers)
      for (const char* ch : kMorphDebugLayers) o.add_channel(ch);
  }
  MorphTimings t;
  method_->run(color, entry_->layers(options_).empty() ? nullptr : gbuffer, entry_->lookahead > 0 ? next : nullptr,
               out, t);
  if (Status s = method_->run_status(); !s) return s;
  if (timings) *timings = t;
  return Status::ok();
}

}  // namespace temporal::morph
