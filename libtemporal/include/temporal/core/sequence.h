// Frame sequences on disk: `name.####.exr` or `name.%04d.exr` patterns and `--frames A-B` ranges.
#pragma once

#include "temporal/core/error.h"

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace temporal {

// A frame range in oiiotool's syntax: "A-B" (every frame), "A" (one frame), "A-BxN" (A, A+N, A+2N, ... up to B:
// every Nth frame) and "A-ByN" (every frame but those of A-BxN: all but every Nth). A 40 -> 120 Hz study scores
// its in-between output frames with "0-47y3" (frames 1, 2, 4, 5, ...) and its rendered ones with "0-47x3".
struct FrameRange {
  int first = 0;
  int last = 0;  // inclusive
  int step = 1;  // x or y: the period N (1: every frame)
  bool complement = false;  // y: every frame but every Nth
  // Parses the forms above; "A-" is refused (the end must be given), so are negative frames, frames above
  // 99,999,999, and N < 1 (usage errors).
  static Expected<FrameRange> parse(std::string_view text);
  // The same without the bounds (for frame lists that may name any frame).
  static Expected<FrameRange> parse_unchecked(std::string_view text);
  // Whether frame f is one of the range.
  bool contains(int f) const {
    if (f < first || f > last) return false;
    const bool on_step = (f - first) % step == 0;
    return complement ? !on_step : on_step;
  }
  // The frames of the range, ascending.
  std::vector<int> frames() const;
  // How many frames frames() returns.
  int count() const;
};

class SequencePattern {
 public:
  // Accepts one run of '#' (the run's length is the zero-padded width, at most 10) or one printf `%0Nd` / `%d`, in
  // the file name (a folder may contain '#' or '%').
  // A path without a placeholder is a single-frame "sequence" (frame numbers are then ignored).
  static Expected<SequencePattern> parse(std::string pattern);

  const std::string& pattern() const { return pattern_; }
  bool has_placeholder() const { return width_ >= 0; }
  // The text before and after the placeholder (the whole pattern is the prefix when there is none), and the
  // zero-padded width (-1: no placeholder; 0: unpadded).
  const std::string& prefix() const { return prefix_; }
  const std::string& suffix() const { return suffix_; }
  int width() const { return width_; }
  std::string path(int frame) const;
  // Frame numbers of the files matching the pattern in its folder, sorted.
  std::vector<int> frames_on_disk() const;

 private:
  std::string pattern_;
  std::string prefix_;
  std::string suffix_;
  int width_ = -1;  // -1: no placeholder; 0: unpadded
};

// `frame` as the suite names its own files, NAME.####.exr: zero-padded to four digits ("0012"), wider numbers in
// full. SequencePattern("NAME.####.exr").path(frame) gives the same digits.
std::string frame_digits(int frame);

// The frames to process: the given range (every file in it must exist), or every frame on disk (which must
// be contiguous: a gap is an error naming the first missing file). An empty result is an error.
Expected<std::vector<int>> resolve_frames(const SequencePattern& pattern, const std::optional<FrameRange>& range);

// Whether the input file `path` exists, without throwing: a path that cannot be examined (a symbolic link loop, a
// folder without search permission) is an Input error naming it ("cannot be examined: ..."), not a
// std::filesystem exception that a tool would report as an internal error.
Expected<bool> input_exists(const std::string& path);

// Parses a comma-separated list of frame numbers and ranges ("10,20-22") into sorted unique frames.
Expected<std::vector<int>> parse_frame_list(std::string_view text);

}  // namespace temporal
