// A method of the upsampling stage as a unit (not installed): its per-method state object and the helpers its
// state files use. Each method's source file defines one MethodEntry (temporal/upsample/methods.h); registry.cpp
// lists them.
#pragma once

#include "temporal/core/stage.h"
#include "upsample_internal.h"
#include "temporal/upsample/methods.h"

#include <memory>
#include <string>
#include <vector>

namespace temporal::upsample {

// "a, b, c" ("(none)" for an empty list): the channel lists of messages and of the state's channel header.
std::string join_names(const std::vector<std::string>& names);

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
  // Whether run() gathers this frame's sample geometry itself, row by row inside its own row pass
  // (low_geometry_row.inc), instead of reading f.lz .. f.lvalid: Upsampler::process then skips its whole-frame
  // gather_low_geometry and leaves those planes empty. A pass of its own over the G-buffer rows of the samples
  // waited on memory (drobot: 5 % of a two-thread frame, docs/upsample-st.md).
  virtual bool gathers_low_geometry() const { return false; }
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

// The registry entry (MethodEntry) is public: temporal/upsample/methods.h.

// --- State files -------------------------------------------------------------------------------------------

// Stores a w x h plane in the top-left corner of channel `name` of `state` (w <= width, h <= height).
void put_plane(Image& state, const std::string& name, const float* src, int w, int h);
void put_uint_plane(Image& state, const std::string& name, const std::uint32_t* src, int w, int h);
// Reads it back into dst (w x h); Input error when the channel is missing. StateValues::Finite: also when a value
// is NaN or infinite - for the planes that every --state-out writes finite (the histories' and drobot's cache's
// payload, its frame counts), where such a value would flow into the output (temporal and drobot did: a damaged
// file's NaN reached thousands of output pixels within three frames); the message names the channel and the count.
enum class StateValues { Any, Finite };
Status get_plane(const Image& state, const std::string& name, float* dst, int w, int h,
                 StateValues values = StateValues::Any);
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
