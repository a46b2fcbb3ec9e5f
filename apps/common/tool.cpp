#include "tool.h"

#include "temporal/io/atomic_file.h"
#include "temporal/core/isa.h"
#include "temporal/core/parallel.h"

#include <signal.h>

#include <unistd.h>

#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <set>
#include <type_traits>

#ifndef TEMPORAL_VERSION
#define TEMPORAL_VERSION "0.0.0"
#endif

namespace temporal::tool {

namespace {
// SIGINT / SIGTERM: remove the temporary files of outputs being written (they would otherwise stay behind as
// hidden `.NAME.tmpPID.exr` files), then die of the same signal.
extern "C" void on_termination(int sig) {
  remove_temporary_files();
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}
}  // namespace

int exit_code_for(const Error& error) {
  switch (error.kind) {
    case ErrorKind::Usage: return kExitUsage;
    case ErrorKind::Input: return kExitInput;
    case ErrorKind::Output: return kExitOutput;
    case ErrorKind::Internal: return kExitInternal;
  }
  return kExitInternal;
}

Tool::Tool(std::string name, std::string description) : name_(std::move(name)), app_(std::move(description), name_) {
  app_.option_defaults()->always_capture_default();
  app_.set_version_flag("--version", std::string(name_) + " " TEMPORAL_VERSION);
  app_.add_option("--threads", threads_, "Worker threads; 0 uses every core")
      ->check(CLI::Range(0, 1024).description("in 0..1024"));
  app_.add_flag("--verbose", verbose_, "Print what the tool does to stderr");
  app_.footer(
      "Exit codes: 0 success, 1 usage error, 2 input error, 4 output error, 5 internal error.\n"
      "Conventions (layers, units, motion vectors, jitter): docs/conventions.md");
}

std::string Tool::signature() const { return name_ + " " TEMPORAL_VERSION; }

void Tool::add_params(const ParamList& params, const std::string& group) {
  for (const auto& p : params) {
    const std::string range = param_range_text(p);
    const std::string help = p.help + (range.empty() ? "" : " (" + range + ")");
    CLI::Option* option = std::visit(
        [&](auto* v) -> CLI::Option* {
          using T = std::remove_pointer_t<decltype(v)>;
          if constexpr (std::is_same_v<T, bool>) {
            if (p.inverted)
              return app_.add_flag_callback(p.flag, [v] { *v = false; }, help);  // --no-snap: clears a default-on field
            return app_.add_flag(p.flag, *v, help);
          } else if constexpr (std::is_same_v<T, std::vector<std::string>>) {
            CLI::Option* o = app_.add_option(p.flag, *v, help);
            if (p.separator) o->delimiter(p.separator);
            if (v->empty()) o->default_str("");  // not "[]"
            return o;
          } else {
            // An empty value (`--flag=` or `--flag ""`) is a usage error naming the option: CLI11 would otherwise
            // convert it to 0 (a valid value of many options) or keep an empty string (issue 26).
            return app_.add_option(p.flag, *v, help)->check(CLI::Validator(
                [](const std::string& value) { return value.empty() ? std::string("needs a value, got an empty one") : std::string(); },
                "", "non-empty"));
          }
        },
        p.value);
    // Options are checked after parsing (check_params), so that every range and choice error reads the same; CLI11
    // only converts the text.
    for (const auto& other : p.excludes) option->excludes(other);
    if (const std::string& g = p.group.empty() ? group : p.group; !g.empty()) option->group(g);
    params_.push_back(p);
  }
}

void Tool::add_sequence_options(SequenceOptions& o, const SequenceFlags& f) {
  app_.add_option("--input", o.input, f.input_help)->required();
  if (!f.gbuffer_help.empty()) {
    auto* g = app_.add_option("--gbuffer", o.gbuffer, f.gbuffer_help);
    if (f.gbuffer_required) g->required();
  }
  app_.add_option("--out", o.out, f.out_help)->required();
  add_output(&o.out);
  app_.add_option("--frames", o.frames, "Frames A-B (default: every input frame on disk)");
  if (f.reset_frames)
    app_.add_option("--reset-frames", o.reset_frames,
                    "Frames where every history is discarded, e.g. 10,20-22 (also done where a header has "
                    "temporal:cameraCut = 1)");
  app_.add_option("--compression", o.compression, "EXR compression of the outputs: none | zip | piz");
  if (f.state) {
    app_.add_option("--state-in", o.state_in, "Resume from a state file written by --state-out (same method and options)");
    app_.add_option("--state-out", o.state_out,
                    "Write the state (everything the next frame needs) each frame (pattern with ####) or after the "
                    "last frame only (plain path)");
    add_output(&o.state_out);
  }
}

void Tool::add_output(const std::string* value, bool folder) { outputs_.emplace_back(value, folder); }

RunHooks Tool::hooks() {
  RunHooks h;
  hooks_start_ = std::chrono::steady_clock::now();  // the run starts now: the first frame's rate counts its time
  h.frame_done = [this](int frame, int done, int total) {
    if (!progress_) progress_ = std::make_shared<Progress>(name_, total, hooks_start_);
    progress_->step(frame);
    if (done == total) progress_.reset();  // erase the line before any summary
  };
  h.warning = [this](const std::string& file, const std::string& text) { print_warning(file, text); };
  h.log = [this](const std::string& text) { log(text); };
  return h;
}

int Tool::run(int argc, char** argv, const std::function<Status()>& body) {
  // Every floating-point option has a finite range (core/params.h, issue 26): a Param table without one is the
  // tool's own bug, caught by any run of the tool (its tests included) before the options are read.
  for (const auto& p : params_)
    if (!has_finite_range(p)) {
      print_error(Error::internal(p.flag + " has no finite range in its Param table (please report this)"));
      return kExitInternal;
    }
  for (int i = 1; i < argc; ++i) {
    if (i > 1) command_line_ += ' ';
    command_line_ += argv[i];
  }
  try {
    app_.parse(argc, argv);
  } catch (const CLI::Success& e) {  // --help, --version
    return app_.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << name_ << ": " << e.what() << "\n" << name_ << ": run `" << name_ << " --help` for the options\n";
    return kExitUsage;
  }
  if (Status s = check_params(params_); !s) {
    print_error(s.error());
    std::cerr << name_ << ": run `" << name_ << " --help` for the options\n";
    return kExitUsage;
  }
  std::set<std::string> noted;
  for (const auto& [value, folder] : outputs_) {
    if (value->empty()) continue;
    const std::filesystem::path dir = folder ? std::filesystem::path(*value) : std::filesystem::path(*value).parent_path();
    std::error_code ec;
    if (dir.empty() || std::filesystem::exists(dir, ec) || ec) continue;
    if (noted.insert(dir.lexically_normal().string()).second)
      std::cerr << name_ << ": " << dir.string() << ": note: the folder does not exist; it will be created for the outputs\n";
  }
  // The CPU kernels' instruction set (temporal/core/isa.h): a TEMPORAL_ISA the run cannot honour is said, since the
  // user asked for it (a benchmark of "v2" that ran v4 would mislead); --verbose names the level in force.
  if (const std::string_view note = isa::environment_note(); !note.empty())
    std::cerr << name_ << ": note: " << note << "\n";
  log("CPU kernels: " + std::string(isa::name(isa::active())) +
      (isa::dispatching() ? " (chosen at run time; TEMPORAL_ISA=v2|v3|v4 forces one)" : " (one copy in this build)"));
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction action {};
    action.sa_handler = on_termination;
    sigemptyset(&action.sa_mask);
    sigaction(sig, &action, nullptr);
  }
  // A file-size limit (ulimit -f) must fail the write, not kill the tool: with SIGXFSZ ignored the write returns
  // EFBIG, the writer reports an output error (exit 4) and no file reaches its final name.
  std::signal(SIGXFSZ, SIG_IGN);
  std::optional<ThreadLimit> limit;
  if (threads_ > 0) limit.emplace(threads_);
  try {
    const Status status = body();
    if (status) return kExitOk;
    print_error(status.error());
    if (status.error().kind == ErrorKind::Usage)
      std::cerr << name_ << ": run `" << name_ << " --help` for the options\n";
    return exit_code_for(status.error());
  } catch (const std::bad_alloc&) {
    print_error(Error{ErrorKind::Input, {}, "out of memory: process fewer frames or smaller images"});
    return kExitInput;
  } catch (const std::exception& e) {
    print_error(Error::internal(std::string("unexpected exception: ") + e.what() + " (please report this)"));
    return kExitInternal;
  }
}

void Tool::print_error(const Error& error) const {
  Progress::clear_active();
  if (error.file.empty())
    std::cerr << name_ << ": " << error.message << "\n";
  else
    std::cerr << name_ << ": " << error.file << ": " << error.message << "\n";
}

void Tool::print_warning(const std::string& file, const std::string& message) const {
  Progress::clear_active();
  std::cerr << name_ << ": " << (file.empty() ? "" : file + ": ") << "warning: " << message << "\n";
}

void Tool::log(const std::string& message) const {
  if (!verbose_) return;
  Progress::clear_active();
  std::cerr << name_ << ": " << message << "\n";
}

namespace {
Progress* g_active = nullptr;  // the progress line on the terminal (tools are single-threaded here)

// Three significant digits without an exponent: 0.0123, 0.123, 1.23, 12.3, 123, 1234.
std::string three_digits(double v) {
  char text[64];
  const double a = std::fabs(v);
  const int decimals = a >= 100.0 ? 0 : a >= 10.0 ? 1 : a >= 1.0 ? 2 : a >= 0.1 ? 3 : 4;
  std::snprintf(text, sizeof text, "%.*f", decimals, v);
  return text;
}
}  // namespace

std::string duration_text(double seconds) {
  char text[64];
  if (!(seconds >= 0.0) || !std::isfinite(seconds)) return "?";
  if (seconds < 10.0) std::snprintf(text, sizeof text, "%.1f s", seconds);
  else if (seconds < 60.0) std::snprintf(text, sizeof text, "%.0f s", std::round(seconds));
  else if (seconds < 3600.0) {
    const long s = std::lround(seconds);
    std::snprintf(text, sizeof text, "%ld min %02ld s", s / 60, s % 60);
  } else {
    const long m = std::lround(seconds / 60.0);
    std::snprintf(text, sizeof text, "%ld h %02ld min", m / 60, m % 60);
  }
  return text;
}

std::string progress_text(const std::string& tool, int frame, int done, int total, double elapsed_s) {
  std::string text = tool + ": frame " + std::to_string(frame) + " (" + std::to_string(done) + "/" + std::to_string(total);
  if (done > 0 && elapsed_s >= kProgressRateAfterSeconds) {
    const double rate = double(done) / elapsed_s;
    text += ", " + three_digits(rate) + " frames/s";
    if (done < total) text += ", ETA " + duration_text(double(total - done) / rate);
  }
  return text + ")";
}

Progress::Progress(std::string tool, int total, std::chrono::steady_clock::time_point start, Mode mode,
                   double line_seconds)
    : tool_(std::move(tool)),
      total_(total),
      enabled_(true),
      terminal_(mode == Mode::Terminal || (mode == Mode::Automatic && isatty(STDERR_FILENO) != 0)),
      line_seconds_(line_seconds),
      start_(start) {
  if (terminal_) g_active = this;
}

Progress::~Progress() {
  finish();
  if (g_active == this) g_active = nullptr;
}

void Progress::finish() {
  if (drawn_) std::fprintf(stderr, "\r\033[K");
  if (drawn_) std::fflush(stderr);
  drawn_ = false;
  enabled_ = false;
}

void Progress::clear_active() {
  if (!g_active || !g_active->drawn_) return;
  std::fprintf(stderr, "\r\033[K");
  std::fflush(stderr);
  g_active->drawn_ = false;
}

void Progress::step(int frame) {
  ++done_;
  if (!enabled_) return;
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  if (!terminal_) {
    // A plain line every line_seconds_ (the first once the run has taken that long), and the last one.
    const bool due = s - last_line_s_ >= line_seconds_;
    if (due || (printed_line_ && done_ >= total_)) {
      std::fprintf(stderr, "%s\n", progress_text(tool_, frame, done_, total_, s).c_str());
      std::fflush(stderr);
      last_line_s_ = s;
      printed_line_ = true;
    }
    return;
  }
  g_active = this;
  std::fprintf(stderr, "\r\033[K%s", progress_text(tool_, frame, done_, total_, s).c_str());
  std::fflush(stderr);
  drawn_ = true;
}

}  // namespace temporal::tool
