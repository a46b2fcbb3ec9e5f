// What every tool shares: the standard options (--threads, --verbose, --version, --help), the mapping of
// library errors to `tool: file: message` on stderr and to the documented exit codes, and a progress line.
// No algorithm lives here.
#pragma once

#include "temporal/core/error.h"

#include <CLI/CLI.hpp>

#include <chrono>
#include <functional>
#include <string>

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

  // Parses argv, applies --threads, runs `body` and turns its result into an exit code. Usage errors
  // print the message and a pointer to --help.
  int run(int argc, char** argv, const std::function<Status()>& body);

  // Prints `tool: file: message` (or `tool: message` without a file) to stderr.
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
};

// A single progress line on stderr (`tool: frame 12/40 (8.1 frames/s)`), drawn only when stderr is a
// terminal, erased when done.
class Progress {
 public:
  Progress(std::string tool, int total);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;
  void step(int frame);

 private:
  std::string tool_;
  int total_;
  int done_ = 0;
  bool enabled_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace temporal::tool
