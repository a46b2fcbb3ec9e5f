// Atomic outputs: every file a tool writes is first written to a temporary file beside it and renamed over the
// target when complete, so an interrupted run leaves either the previous file or the new one, never a truncated one
// (docs/conventions.md). Temporary files are hidden (`.NAME.tmpPID.EXT`, so sequence scans never see them), are
// removed when writing fails, when a tool is stopped by SIGINT/SIGTERM (remove_temporary_files), and when a later
// run writes the same target and finds temporaries of processes that no longer exist.
#pragma once

#include "temporal/core/error.h"

#include <string>

namespace temporal {

class TemporaryFile {
 public:
  // Creates the target's folder if missing, removes stale temporaries of the same target left by dead
  // processes, and registers the temporary name for removal on a signal.
  explicit TemporaryFile(const std::string& target);
  ~TemporaryFile();  // removes the temporary file unless committed
  TemporaryFile(const TemporaryFile&) = delete;
  TemporaryFile& operator=(const TemporaryFile&) = delete;

  // Where to write: `.NAME.tmpPID.EXT` in the target's folder (the extension is kept so that writers that pick a
  // format by extension, OpenImageIO and VTK, pick the right one).
  const std::string& path() const { return temporary_; }
  const std::string& target() const { return target_; }
  // Renames the temporary file over the target. Output error when the rename fails.
  Status commit();

 private:
  std::string target_, temporary_;
  int slot_ = -1;
  bool committed_ = false;
};

// Writes `text` to `path` atomically. Output error when it cannot.
Status write_text_atomic(const std::string& path, const std::string& text);

// Removes every registered temporary file of this process. Async-signal-safe (only unlink): a tool's SIGINT /
// SIGTERM handler calls it before the process ends.
void remove_temporary_files() noexcept;

}  // namespace temporal
