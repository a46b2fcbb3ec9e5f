// Temporal profiles (temporal/pictures/profile.h).
#include "temporal/pictures/profile.h"

#include <charconv>

namespace temporal {

Expected<int> ProfileLine::resolve(int width, int height) const {
  const int length = axis == ProfileAxis::Row ? height : width;
  const int i = index < 0 ? length / 2 : index;
  if (i >= length)
    return Error::usage(std::string("--profile ") + (axis == ProfileAxis::Row ? "row " : "column ") + std::to_string(i) +
                        " is outside the " + std::to_string(width) + "x" + std::to_string(height) + " image");
  return i;
}

std::string ProfileLine::describe(int width, int height) const {
  auto i = resolve(width, height);
  return std::string(axis == ProfileAxis::Row ? "row " : "column ") + (i ? std::to_string(*i) : std::string("?"));
}

Expected<ProfileLine> parse_profile_line(std::string_view text) {
  ProfileLine line;
  std::string_view rest;
  if (text.rfind("row", 0) == 0) {
    line.axis = ProfileAxis::Row;
    rest = text.substr(3);
  } else if (text.rfind("column", 0) == 0) {
    line.axis = ProfileAxis::Column;
    rest = text.substr(6);
  } else {
    return Error::usage("--profile '" + std::string(text) + "' is not row:Y, column:X, row or column");
  }
  if (rest.empty()) return line;
  int v = -1;
  auto [end, ec] = std::from_chars(rest.data() + 1, rest.data() + rest.size(), v);
  if (rest[0] != ':' || ec != std::errc() || end != rest.data() + rest.size() || v < 0)
    return Error::usage("--profile '" + std::string(text) + "' is not row:Y, column:X, row or column (Y, X >= 0)");
  line.index = v;
  return line;
}

Status TemporalProfile::add(std::span<const float* const> planes, int width, int height) {
  if (planes.size() != channels_.size()) return Error::internal("TemporalProfile::add: wrong number of planes");
  if (frames_ == 0) {
    auto i = line_.resolve(width, height);
    if (!i) return i.error();
    width_ = width;
    height_ = height;
    index_ = *i;
    data_.assign(channels_.size(), {});
  } else if (width != width_ || height != height_) {
    return Error::input({}, "a frame's size differs from the first frame's; a temporal profile needs one size");
  }
  for (std::size_t c = 0; c < planes.size(); ++c) {
    const float* p = planes[c];
    auto& d = data_[c];
    if (line_.axis == ProfileAxis::Row) {
      d.insert(d.end(), p + std::size_t(index_) * std::size_t(width), p + std::size_t(index_ + 1) * std::size_t(width));
    } else {
      for (int y = 0; y < height; ++y) d.push_back(p[std::size_t(y) * std::size_t(width) + std::size_t(index_)]);
    }
  }
  ++frames_;
  return {};
}

Image TemporalProfile::image() const {
  if (frames_ == 0) return Image();
  const bool row = line_.axis == ProfileAxis::Row;
  const int length = row ? width_ : height_;
  const int w = row ? length : int(frames_), h = row ? int(frames_) : length;
  Image out(w, h);
  for (std::size_t c = 0; c < channels_.size(); ++c) {
    float* dst = out.add_channel(channels_[c]);
    const auto& d = data_[c];
    for (std::size_t f = 0; f < frames_; ++f)
      for (int i = 0; i < length; ++i) {
        const float v = d[f * std::size_t(length) + std::size_t(i)];
        if (row) dst[f * std::size_t(w) + std::size_t(i)] = v;        // x to the right, time down
        else dst[std::size_t(i) * std::size_t(w) + f] = v;            // time to the right, y down
      }
  }
  return out;
}

}  // namespace temporal
