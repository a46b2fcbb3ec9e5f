// Frame sequences on disk: `name.####.exr` or `name.%04d.exr` patterns and `--frames A-B` ranges.
#pragma once

#include "temporal/core/error.h"

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace temporal {

struct FrameRange {
  int first = 0;
  int last = 0;  // inclusive
  // Parses "A-B" or "A" (one frame); "A-" is refused (the end must be given), so are negative frames and frames
  // above 99,999,999 (usage errors).
  static Expected<FrameRange> parse(std::string_view text);
  // The same without the bounds (for frame lists that may name any frame).
  static Expected<FrameRange> parse_unchecked(std::string_view text);
  int count() const { return last - first + 1; }
};

class SequencePattern {
 public:
  // Accepts one run of '#' (the run's length is the zero-padded width, at most 10) or one printf `%0Nd` / `%d`, in
  // the file name (a folder may contain '#' or '%').
  // A path without a placeholder is a single-frame "sequence" (frame numbers are then ignored).
  static Expected<SequencePattern> parse(std::string pattern);

  const std::string& pattern() const { return pattern_; }
  bool has_placeholder() const { return width_ >= 0; }
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

// Parses a comma-separated list of frame numbers and ranges ("10,20-22") into sorted unique frames.
Expected<std::vector<int>> parse_frame_list(std::string_view text);

}  // namespace temporal
