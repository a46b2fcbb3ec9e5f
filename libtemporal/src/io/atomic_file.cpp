// Atomic outputs (temporal/io/atomic_file.h).
#include "temporal/io/atomic_file.h"

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace temporal {
namespace {

namespace fs = std::filesystem;

// The registry of temporary files a signal handler removes: fixed slots of fixed size, claimed and released with
// atomics, so that the handler reads them without locks or allocation.
constexpr int kSlots = 64;
constexpr std::size_t kPathMax = 4096;
struct Slot {
  std::atomic<int> state{0};  // 0 free, 1 being written, 2 holds a path
  char path[kPathMax];
};
Slot g_slots[kSlots];

int claim(const std::string& path) {
  if (path.size() >= kPathMax) return -1;
  for (int i = 0; i < kSlots; ++i) {
    int expected = 0;
    if (g_slots[i].state.compare_exchange_strong(expected, 1)) {
      std::memcpy(g_slots[i].path, path.c_str(), path.size() + 1);
      g_slots[i].state.store(2);
      return i;
    }
  }
  return -1;  // more than kSlots files in flight: still written atomically, just not removed on a signal
}

void release(int slot) {
  if (slot >= 0) g_slots[slot].state.store(0);
}

// `.NAME.tmp` + PID + EXT for the target NAME (EXT: NAME's extension, kept for format detection).
std::string temporary_name(const fs::path& target, long pid) {
  std::string name(".");  // appended piece by piece: `"." + std::string` trips a false -Wrestrict in GCC 12
  name.append(target.filename().string()).append(".tmp").append(std::to_string(pid)).append(target.extension().string());
  return name;
}

// Removes `.NAME.tmp<PID><EXT>` files of the same target whose process no longer exists.
void remove_stale(const fs::path& target) {
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  const std::string prefix = std::string(".").append(target.filename().string()).append(".tmp");
  const std::string ext = target.extension().string();
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.size() <= prefix.size() + ext.size() || name.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string digits = name.substr(prefix.size(), name.size() - prefix.size() - ext.size());
    if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos ||
        name.compare(name.size() - ext.size(), ext.size(), ext) != 0)
      continue;
    const long pid = std::strtol(digits.c_str(), nullptr, 10);
    if (pid == long(getpid())) continue;
    if (kill(pid_t(pid), 0) != 0 && errno == ESRCH) fs::remove(it->path(), ec);
  }
}

}  // namespace

TemporaryFile::TemporaryFile(const std::string& target) : target_(target) {
  const fs::path t(target);
  std::error_code ec;
  if (t.has_parent_path()) fs::create_directories(t.parent_path(), ec);
  remove_stale(t);
  temporary_ = (t.parent_path() / temporary_name(t, long(getpid()))).string();
  slot_ = claim(temporary_);
}

TemporaryFile::~TemporaryFile() {
  if (!committed_) {
    std::error_code ec;
    fs::remove(temporary_, ec);
  }
  release(slot_);
}

Status TemporaryFile::commit() {
  std::error_code ec;
  // rename() would replace a device node, a socket or a pipe by the file (as root, even /dev/null's twin): only a
  // regular file or a new name may be written.
  if (const fs::file_status st = fs::status(target_, ec); !ec && fs::exists(st) && !fs::is_regular_file(st))
    return Error::output(target_, "exists and is not a regular file: name a new file or a regular one to replace");
  fs::rename(temporary_, target_, ec);
  if (ec) return Error::output(target_, "cannot move the finished file into place: " + ec.message());
  committed_ = true;
  return Status::ok();
}

Status write_text_atomic(const std::string& path, const std::string& text) {
  TemporaryFile tmp(path);
  {
    std::ofstream out(tmp.path(), std::ios::binary | std::ios::trunc);
    out << text;
    out.close();  // close() flushes; its failure (a full disk) sets failbit, checked below
    if (!out) return Error::output(path, "cannot write (is the disk full or the folder read-only?)");
    std::error_code ec;
    if (fs::file_size(tmp.path(), ec) != text.size() || ec)
      return Error::output(path, "cannot write the whole file (is the disk full or a file-size limit reached?)");
  }
  return tmp.commit();
}

void remove_temporary_files() noexcept {
  for (auto& s : g_slots)
    if (s.state.load() == 2) unlink(s.path);
}

}  // namespace temporal
