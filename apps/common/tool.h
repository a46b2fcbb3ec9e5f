// What every tool shares: the standard options (--threads, --verbose, --version, --help), the mapping of
// library errors to `tool: file: message` on stderr and to the documented exit codes, and a progress line.
// No algorithm lives here.
#pragma once

#include "temporal/core/error.h"
#include "temporal/core/params.h"
#include "temporal/io/runner.h"

#include <CLI/CLI.hpp>

#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace temporal::tool {

// Exit codes shared by every tool (docs/cli.md).
enum ExitCode : int {
  kExitOk = 0,
  kExitUsage = 1,      // bad command line
  kExitInput = 2,      // unreadable, corrupt, mismatched or missing input
  kExitThreshold = 3,  // a --fail-* threshold was crossed (compare)
  kExitOutput = 4,     // an output could not be written
  kExitInternal = 5,   // a bug: please report it
};

int exit_code_for(const Error& error);

class Tool {
 public:
  Tool(std::string name, std::string description);

  CLI::App& app() { return app_; }
  const std::string& name() const { return name_; }
  int threads() const { return threads_; }
  bool verbose() const { return verbose_; }
  // The command line as given, for the `temporal:parameters` header attribute.
  const std::string& command_line() const { return command_line_; }
  // "name version", for the `temporal:tool` header attribute.
  std::string signature() const;

  // Adds every parameter of a method (temporal/core/params.h) as an option: the help shows the default (from
  // the library's option struct) and the valid range; after parsing, out-of-range and non-finite values and
  // values that are not one of the choices are usage errors (exit 1) with the range in the message. `group`: the
  // --help section of the parameters that do not name their own (Param::group), e.g. a method's name; empty: the
  // general options.
  void add_params(const ParamList& params, const std::string& group = {});

  // The standard options of a sequence tool (docs/cli.md), bound to `options`. `gbuffer_help` empty: no
  // --gbuffer; `state` adds --state-in / --state-out.
  struct SequenceFlags {
    std::string input_help;
    std::string gbuffer_help;
    std::string out_help;
    bool gbuffer_required = false;
    bool reset_frames = true;
    bool state = false;
  };
  void add_sequence_options(SequenceOptions& options, const SequenceFlags& flags);

  // An output option's value: a file or a frame pattern (`folder` false: its folder is the parent) or a folder.
  // Before the run, each folder that does not exist yet is named on stderr (`tool: DIR: note: ...`): it is created
  // for the outputs, as every tool does, but not silently (issue 25: `--out /nonexistent/a.####.exr`).
  void add_output(const std::string* value, bool folder = false);

  // Hooks that draw the progress line, print warnings and --verbose lines (temporal/io/runner.h).
  RunHooks hooks();
  // `temporal:tool` / `temporal:parameters` of the outputs.
  RunIdentity identity() const { return {signature(), command_line_}; }

  // Parses argv, applies --threads, runs `body` and turns its result into an exit code. Usage errors
  // print the message and a pointer to --help.
  int run(int argc, char** argv, const std::function<Status()>& body);

  // Prints `tool: file: message` (or `tool: message` without a file) to stderr. These three erase a progress line
  // first, so a message never lands glued to it (the next step draws the line again).
  void print_error(const Error& error) const;
  void print_warning(const std::string& file, const std::string& message) const;
  // Prints to stderr only with --verbose.
  void log(const std::string& message) const;

 private:
  std::string name_;
  std::string command_line_;
  CLI::App app_;
  int threads_ = 0;
  bool verbose_ = false;
  ParamList params_;
  std::vector<std::pair<const std::string*, bool>> outputs_;
  std::shared_ptr<class Progress> progress_;
  std::chrono::steady_clock::time_point hooks_start_;
};

// The text of a progress line: `tool: frame 12 (13/40, 8.12 frames/s, ETA 3 s)`. The rate and the time left
// are shown once `elapsed_s` (since the run started, before the first frame) reaches kProgressRateAfterSeconds:
// over a shorter time they would be noise (a first frame done in 60 ns of a started clock read as
// "16666666.7 frames/s"). Rates and times keep three significant digits, never an exponent.
inline constexpr double kProgressRateAfterSeconds = 0.5;
std::string progress_text(const std::string& tool, int frame, int done, int total, double elapsed_s);
// A duration for people: "0.4 s", "12 s", "3 min 05 s", "1 h 02 min".
std::string duration_text(double seconds);

// Progress on stderr (progress_text). On a terminal: one line, redrawn at each frame and erased when done
// (destructor, or finish()) or before any message the Tool prints. Elsewhere (a log file, a Snakemake or Slurm
// job log): one plain line every kProgressLineSeconds once the run has taken that long, and a last line at the end
// if any was printed - so a long render shows that it advances, and a short run prints nothing. One progress is
// active per process at a time.
inline constexpr double kProgressLineSeconds = 5.0;
class Progress {
 public:
  enum class Mode { Automatic, Terminal, Lines };
  // `start`: when the work began (default: now), so the first frame's rate counts its own time. Automatic:
  // Terminal when stderr is a terminal, else Lines. `line_seconds`: the interval of Lines.
  Progress(std::string tool, int total,
           std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now(),
           Mode mode = Mode::Automatic, double line_seconds = kProgressLineSeconds);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;
  void step(int frame);
  // Erases the line now (it is not drawn again).
  void finish();
  // Erases the active progress line, if one is drawn (before printing anything else to the terminal).
  static void clear_active();

 private:
  std::string tool_;
  int total_;
  int done_ = 0;
  bool enabled_;
  bool terminal_;
  bool drawn_ = false;
  double line_seconds_;
  double last_line_s_ = 0.0;  // when the last plain line was printed (seconds since start_)
  bool printed_line_ = false;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace temporal::tool
