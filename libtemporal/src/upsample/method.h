// A method of the upsampling stage as a unit (not installed): its registry entry, its per-method state object,
// and the helpers its state files use. Each method's source file defines one MethodEntry; registry.cpp lists them.
#pragma once

#include "temporal/core/stage.h"
#include "upsample_internal.h"
#include "temporal/upsample/methods.h"

#include <memory>
#include <string>
#include <vector>

namespace temporal::upsample {

// The sizes a method's state is allocated for; a change discards the history and re-creates the state.
struct Geometry {
  int W = 0, H = 0, k = 0, lw = 0, lh = 0;
  std::vector<std::string> channels;
  bool operator==(const Geometry&) const = default;
};

// A method's state: everything it keeps between frames (histories, weights, gradients, the previous depth and
// ids), its output images, and its per-frame work.
class MethodState {
 public:
  virtual ~MethodState() = default;
  // Upsamples one frame of `f` (full resolution) into an image owned by the state, valid until the next call:
  // the payload channels, plus debug.* layers when f.debug. `history` is false when every history must be ignored
  // (first frame, cut). Fills stats.hole_pixels and stats.history_pixels.
  virtual Image& run(const FrameContext& f, bool history, FrameStats& stats) = 0;
  // Whether the last run() succeeded: the C++ states cannot fail; a GPU state (gpu_methods.h) reports a driver
  // error here (its output is then undefined), and the Upsampler returns it.
  virtual Status run_status() const { return Status::ok(); }
  // The persistent state as planes of `state` (an image at the G-buffer's size; smaller planes top-left, see
  // put_plane) and header attributes that describe its layout (checked on load).
  virtual void save(Image& state) const = 0;
  // Restores what save() wrote; an Input error names the missing or mismatched plane.
  virtual Status load(const Image& state) = 0;
};

// The G-buffer layers of a method that reprojects a history (temporal, herzog, drobot, taau): depth and N for the
// samples' geometry, motion for the fetch, the ids of the disocclusion test unless --no-ids, and the warped depth
// prevDepth.Z when the G-buffer has it (optional; not read with --no-depth-velocity).
inline std::vector<LayerNeed> history_method_layers(const Options& o) {
  std::vector<LayerNeed> l = {{"depth"}, {"N"}, {"motion"}};
  if (!o.no_ids) l.push_back({"id", true, "or pass --no-ids"});
  if (!o.no_depth_velocity) l.push_back({"prevDepth", false});
  return l;
}

// One row of the registry (docs/upsample-st.md, "Methods as units").
struct MethodEntry {
  MethodInfo info;
  // The method's own parameters with their defaults (nullptr: none).
  std::unique_ptr<MethodOptions> (*make_options)() = nullptr;
  // G-buffer layers it reads (albedo for demodulation is added by the Upsampler).
  std::vector<LayerNeed> (*layers)(const Options&) = nullptr;
  // A new state for frames of this geometry (nullptr: the method keeps nothing between frames except its output).
  std::unique_ptr<MethodState> (*make_state)(const Options&, const Geometry&) = nullptr;
  // Bytes per frame it must at least read and write (the benchmark's streaming bound): G-buffer planes, payload in
  // and out, histories read and written once. W, H full resolution, k the factor, C payload channels.
  std::size_t (*streamed_bytes)(const Options&, int W, int H, int k, int C) = nullptr;
  // Header attributes of a state that must match the options of the run that loads it ("mode=cache"); empty when
  // the state does not depend on the options.
  std::string (*state_layout)(const Options&) = nullptr;
  // The `temporal:method` header value when it is more than the name ("drobot-refresh"); nullptr: the name.
  std::string (*header_name)(const Options&) = nullptr;
};

// The table (registry.cpp), and the entry called `name` (nullptr when unknown).
const std::vector<const MethodEntry*>& registry();
const MethodEntry* find_entry(const std::string& name);

// A method's options struct T (fields with defaults, `ParamList params()`, optionally `Status check() const`)
// as MethodOptions, and the typed view of it inside Options.
template <typename T>
class OptionsOf : public MethodOptions, public T {
 public:
  std::unique_ptr<MethodOptions> clone() const override { return std::make_unique<OptionsOf>(*this); }
  ParamList params() override { return T::params(); }
  Status check() const override {
    if constexpr (requires(const T& t) { t.check(); })
      return T::check();
    else
      return Status::ok();
  }
  static std::unique_ptr<MethodOptions> make() { return std::make_unique<OptionsOf>(); }
};
template <typename T>
const T& method_options(const Options& o, const std::string& name) {
  static const OptionsOf<T> defaults;
  const MethodOptions* m = o.per_method.find(name);
  return m ? static_cast<const OptionsOf<T>&>(*m) : defaults;
}

// --- State files -------------------------------------------------------------------------------------------

// Stores a w x h plane in the top-left corner of channel `name` of `state` (w <= width, h <= height).
void put_plane(Image& state, const std::string& name, const float* src, int w, int h);
void put_uint_plane(Image& state, const std::string& name, const std::uint32_t* src, int w, int h);
// Reads it back into dst (w x h); Input error when the channel is missing.
Status get_plane(const Image& state, const std::string& name, float* dst, int w, int h);
Status get_uint_plane(const Image& state, const std::string& name, std::uint32_t* dst, int w, int h);

// The previous frame's depth and ids as `prev.depth` / `prev.id` of a state.
void put_previous(Image& state, const PreviousGeometry& prev, int W, int H);
Status get_previous(const Image& state, PreviousGeometry& prev, int W, int H);

// Two images written in turn: this frame's output, the previous one (the history of temporal, herzog and drobot
// refresh). Channels are the payload's; debug layers are added by the methods.
class OutputPair {
 public:
  OutputPair(const Geometry& g);
  Image& next() {
    cur_ = 1 - cur_;
    return img_[cur_];
  }
  Image& current() { return img_[cur_]; }
  const Image& current() const { return img_[cur_]; }
  const Image& previous() const { return img_[1 - cur_]; }
  int index() const { return cur_; }

 private:
  Image img_[2];
  int cur_ = 0;
};

// The payload planes of `img` in channel order.
std::vector<float*> payload_planes(Image& img, const std::vector<std::string>& channels);
std::vector<const float*> payload_planes(const Image& img, const std::vector<std::string>& channels);

}  // namespace temporal::upsample
