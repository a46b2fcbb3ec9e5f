// Temporal profiles: one line of every frame stacked over time, the standard picture of flicker (a noisy
// profile), ghosting (trails behind moving edges) and temporal lag. A row's profile is an x-t image (x to the
// right, time down, one pixel row per frame); a column's is a y-t image (time to the right, y down).
#pragma once

#include "temporal/core/error.h"
#include "temporal/core/image.h"

#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace temporal {

enum class ProfileAxis { Row, Column };

struct ProfileLine {
  ProfileAxis axis = ProfileAxis::Row;
  int index = -1;  // row y or column x; -1: the middle of the image
  // The row or column used in a width x height image; Usage error when it lies outside.
  Expected<int> resolve(int width, int height) const;
  // "row 128" / "column 64" (after resolve).
  std::string describe(int width, int height) const;
};
// Parses `row:Y`, `column:X`, `row` or `column` (the middle).
Expected<ProfileLine> parse_profile_line(std::string_view text);

class TemporalProfile {
 public:
  // `channels`: names of the output channels, one per plane added (e.g. R, G, B).
  TemporalProfile(ProfileLine line, std::vector<std::string> channels) : line_(line), channels_(std::move(channels)) {}
  // Appends this frame's line of each plane (width * height floats each; as many planes as channels). The first
  // frame fixes the size; Input error when a later frame differs, or for a line outside the image.
  Status add(std::span<const float* const> planes, int width, int height);
  std::size_t frames() const { return frames_; }
  // The profile image (empty before the first frame). Row profile: line length x frames; column: frames x length.
  Image image() const;

 private:
  ProfileLine line_;
  std::vector<std::string> channels_;
  int width_ = 0, height_ = 0, index_ = 0;
  std::size_t frames_ = 0;
  std::vector<std::vector<float>> data_;  // per channel: frame-major lines
};

}  // namespace temporal
