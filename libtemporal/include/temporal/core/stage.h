// What a per-frame method looks like to the sequence runner (temporal/io/runner.h): the layers it reads, the
// frame it is handed, the outputs it returns, its persistent state. These types involve no file I/O, so that a
// stage's kernels and their benchmarks link without an image library; the runner that reads and writes the
// files lives in the io stage.
#pragma once

#include "temporal/core/error.h"
#include "temporal/core/image.h"

#include <cstddef>
#include <limits>
#include <map>
#include <string>
#include <vector>

namespace temporal {

// One G-buffer layer a stage reads, and what the user should do when it is missing.
struct LayerNeed {
  std::string layer;  // "motion", "depth", "N", "id", "albedo"
  bool required = true;
  std::string alternative = {};  // appended to the message when it is missing, e.g. "or pass --no-ids"
};

// What a stage reads and how its inputs relate.
struct StageInputs {
  std::vector<std::string> input_layers;    // selection of the input (read_exr); empty: every layer
  std::vector<LayerNeed> gbuffer_layers;    // G-buffer layers; empty: no G-buffer read
  bool gbuffer_required = false;            // refuse to run without --gbuffer
  std::string gbuffer_purpose;              // for the message when it is missing: "the motion of the history fetch"
  // The G-buffer is `gbuffer_scale` times the input per axis (1: same size; upsample-st: k from the header).
  // 0: the scale is read from the input header's temporal:jitterFactor.
  int gbuffer_scale = 1;
  // Frames after the current one the stage sees (morph-120hz blend: 1; --perceive: the eye's window - 1), read
  // from disk even past the selected range while the files exist (unless lookahead_past_range is false: then
  // only frames of the list are read, and the last frame of the list sees none).
  int lookahead = 0;
  bool lookahead_past_range = true;
  // Outputs the stage writes per input frame (morph-120hz: factor); above 1, --out must have a placeholder.
  int outputs_per_frame = 1;
};

// One frame handed to a stage.
struct StageFrame {
  int frame = 0;
  std::size_t index = 0;  // position in the frame list
  std::size_t count = 0;  // frames in the list
  bool cut = false;       // discard every history before this frame
  const Image* input = nullptr;
  const Image* gbuffer = nullptr;          // null when no G-buffer was given
  std::vector<const Image*> next;          // lookahead frames that exist (in order)
  std::string input_path, gbuffer_path;
};

// One output of a frame: the image (owned by the stage, valid until the next call) and its frame number.
struct StageOutput {
  int frame = 0;
  Image* image = nullptr;
  double compute_ms = 0.0;                    // `temporal:computeMs` (the stage's compute time, I/O excluded)
  std::map<std::string, std::string> extra;   // `temporal:<key>` attributes (method, counters)
  std::vector<std::string> drop_extra;        // `temporal:<key>` attributes of the input header not carried over
  std::map<std::string, double> timings_ms;   // `temporal:ms:<pass>`
  bool keep_input_metadata = true;            // start from the input header (camera, fps, time, clip)
};

// A method run by the runner: a filter, an upsampler, a frame-rate converter.
class FrameStage {
 public:
  virtual ~FrameStage() = default;
  virtual const StageInputs& inputs() const = 0;
  // Processes one frame; appends its outputs (usually one; morph-120hz: `factor` of them) to `out`.
  virtual Status process(const StageFrame& frame, std::vector<StageOutput>& out) = 0;
  // Persistent state (histories, models), for --state-out / --state-in. Stages without state return an empty
  // image from save_state and refuse load_state. `source` (the --state-in file) names the file in the errors a
  // stage finds when it applies the state later, at the first frame, whose size it needs: without it they would
  // name that frame's input.
  virtual bool has_state() const { return false; }
  virtual Expected<Image> save_state() const { return Image(); }
  virtual Status load_state(const Image& state, const std::string& /*source*/) {
    return Error::usage("this method has no state: drop --state-in / --state-out");
  }
  // One line for --verbose after each frame ("3.1 ms, 120 pixels without history").
  virtual std::string frame_summary() const { return {}; }
};

// The channels a G-buffer layer name stands for ("N" -> N.X, N.Y, N.Z; "id" -> id); empty for a name that is not
// one of the G-buffer's layers.
std::vector<std::string> layer_channel_names(const std::string& layer);

// Checks that a G-buffer frame has every required layer, with one message per missing layer that says how to
// produce it. `path` names the file in the error.
Status check_gbuffer_layers(const Image& gbuffer, const std::vector<LayerNeed>& needs, const std::string& path);

// Pixels of `image` with a NaN or Inf in any float plane of the named layers (every float plane when empty; "rgb"
// stands for R, G, B), or a value of magnitude above `max_magnitude` (the colour inputs: kMaxSampleMagnitude, the
// samples the methods refuse, temporal/core/image.h).
std::size_t count_non_finite_layers(const Image& image, const std::vector<std::string>& layers,
                                    float max_magnitude = std::numeric_limits<float>::infinity());

}  // namespace temporal
