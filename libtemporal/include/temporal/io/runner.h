// The sequence runner (io stage): the per-frame loop that every tool which reads a frame sequence and writes one shares
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
#include "temporal/core/stage.h"
#include "temporal/io/exr.h"
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
  // Further files or patterns the stage reads itself (morph-120hz --lag-reference): protected like the inputs,
  // so that no output replaces one of them.
  std::vector<std::string> other_inputs;
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

// The outputs of one run by the files they name: no two options may name the same file (a frame pattern names
// every file it can produce), and an output that exists must be a regular file (writing would replace a device,
// a folder or a socket by a file). Folders are compared after resolving links.
class OutputPaths {
 public:
  // Registers `path` (a file or a frame pattern) of option `what`; Usage error naming both options when it can
  // name a file that an output registered before names, or when it is an existing path that is not a regular file.
  Status add(const std::string& path, const std::string& what);

 private:
  struct Entry {
    std::string folder, prefix, suffix, what, text;
    bool pattern = false;
  };
  std::vector<Entry> entries_;
};

// The output compression of a data sequence: `none`, `zip`, `piz`; `dwaa` is refused (lossy on data).
Expected<ExrCompression> parse_data_compression(const std::string& name);

}  // namespace temporal
