// The sequence runner: the per-frame loop that every tool which reads a frame sequence and writes one shares
// (upsample-st, filter-phlm, morph-120hz; compare has its own engine built from the same pieces). The library
// owns the loop; a tool supplies a FrameStage (the method) and hooks (progress, warnings, --verbose lines).
//
// What the runner does, once for every tool, with one message per failure:
//  - patterns (`--input`, `--gbuffer`, `--out`, docs/conventions.md) and the frame list (`--frames A-B`, or every
//    input frame on disk, contiguous); every G-buffer file of the list must exist before any work is done;
//  - history resets: the first frame (unless a state was loaded), `--reset-frames`, `temporal:cameraCut` in the
//    input's or the G-buffer's header, and a gap in the frame numbers;
//  - reading only the layers the stage needs, with the G-buffer checks (layers present, sizes consistent);
//  - counting non-finite values of the inputs and reporting them as warnings;
//  - stamping every output header (tool, command line, frame, compute time of the stage, method) and writing it
//    atomically with the chosen compression (DWA refused for data);
//  - `--state-in` / `--state-out`: a stage with persistent state saves and resumes it, bit for bit.
#pragma once

#include "temporal/core/error.h"
#include "temporal/core/exr.h"
#include "temporal/core/image.h"
#include "temporal/core/sequence.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace temporal {

// The options every sequence tool takes (the CLI binds to these fields; the defaults are here).
struct SequenceOptions {
  std::string input;         // --input pattern
  std::string gbuffer;       // --gbuffer pattern (empty: none)
  std::string out;           // --out pattern
  std::string frames;        // --frames A-B (empty: every input frame on disk)
  std::string reset_frames;  // --reset-frames "10,20-22"
  std::string compression = "zip";  // none | zip | piz (dwaa refused: outputs are data)
  std::string state_in;      // --state-in FILE (empty: none)
  std::string state_out;     // --state-out FILE or pattern (empty: none)
};

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
  // image from save_state and refuse load_state.
  virtual bool has_state() const { return false; }
  virtual Expected<Image> save_state() const { return Image(); }
  virtual Status load_state(const Image& state) {
    return Error::usage("this method has no state: drop --state-in / --state-out");
  }
  // One line for --verbose after each frame ("3.1 ms, 120 pixels without history").
  virtual std::string frame_summary() const { return {}; }
};

// Observers of a run (the library never prints: the tool decides).
struct RunHooks {
  std::function<void(int frame, int done, int total)> frame_done;
  std::function<void(const std::string& file, const std::string& text)> warning;
  std::function<void(const std::string& text)> log;
};

// Who writes the outputs: `temporal:tool` and `temporal:parameters`.
struct RunIdentity {
  std::string tool;        // "upsample-st 0.1.0"
  std::string parameters;  // the command line
};

struct RunSummary {
  std::size_t frames = 0;
  std::size_t outputs = 0;
  std::size_t non_finite_input = 0;
  std::size_t non_finite_gbuffer = 0;
  double compute_ms = 0.0;  // sum of the stage's compute time
};

// Runs `stage` over the sequence. Errors: Usage (patterns, options), Input (missing, corrupt or mismatched files,
// missing layers), Output (files not writable). The first error stops the run; outputs already written stay.
Expected<RunSummary> run_sequence(const SequenceOptions& options, FrameStage& stage, const RunIdentity& identity,
                                  const RunHooks& hooks = {});

// --- Pieces shared with compare ----------------------------------------------------------------------------

// The files a run reads, by identity (device and inode), so that no output ever replaces one of them: an output
// pattern equal to an input pattern, another spelling of the same path, a hard or symbolic link to an input.
class ProtectedInputs {
 public:
  void add(const std::string& path);  // ignored when the file does not exist
  // Usage error when `path` exists and is one of the inputs; `what` names the option ("--out").
  Status check(const std::string& path, const std::string& what) const;

 private:
  std::set<std::pair<std::uint64_t, std::uint64_t>> ids_;
};

// The output compression of a data sequence: `none`, `zip`, `piz`; `dwaa` is refused (lossy on data).
Expected<ExrCompression> parse_data_compression(const std::string& name);

// Checks that a G-buffer frame has every required layer, with one message per missing layer that says how to
// produce it. `path` names the file in the error.
Status check_gbuffer_layers(const Image& gbuffer, const std::vector<LayerNeed>& needs, const std::string& path);

// Pixels of `image` with a NaN or Inf in any float plane of the named layers (every float plane when empty; "rgb"
// stands for R, G, B).
std::size_t count_non_finite_layers(const Image& image, const std::vector<std::string>& layers);

}  // namespace temporal
