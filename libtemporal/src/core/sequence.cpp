#include "temporal/core/sequence.h"

#include <algorithm>
#include <charconv>
#include <filesystem>
#include <set>

namespace temporal {
namespace {

bool parse_int(std::string_view s, int& out) {
  if (s.empty()) return false;
  const auto* end = s.data() + s.size();
  auto [p, ec] = std::from_chars(s.data(), end, out);
  return ec == std::errc() && p == end;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && s.front() == ' ') s.remove_prefix(1);
  while (!s.empty() && s.back() == ' ') s.remove_suffix(1);
  return s;
}

// Frame numbers the tools accept: 0 .. kMaxFrame (a run of eight digits; larger numbers are a typing error, and
// loops over them would not end in any useful time).
constexpr int kMaxFrame = 99'999'999;

// A pattern for messages: long ones are cut (a mistyped width can make them megabytes long).
std::string shown(const std::string& pattern) {
  return pattern.size() <= 200 ? pattern : pattern.substr(0, 200) + "...";
}

}  // namespace

Expected<FrameRange> FrameRange::parse(std::string_view text) {
  auto checked = parse_unchecked(text);
  if (!checked) return checked;
  if (checked->first < 0)
    return Error::usage("--frames " + std::string(trim(text)) + ": frames are numbered from 0 (frame N is time N / fps)");
  if (checked->last > kMaxFrame)
    return Error::usage("--frames " + std::string(trim(text)) + ": frame numbers above " + std::to_string(kMaxFrame) +
                        " are not supported");
  return checked;
}

std::vector<int> FrameRange::frames() const {
  std::vector<int> out;
  for (int f = first; f <= last && f >= first; ++f)  // f >= first: no wrap at INT_MAX
    if (contains(f)) out.push_back(f);
  return out;
}

int FrameRange::count() const {
  const long long all = (long long)last - first + 1;
  const long long on_step = (all + step - 1) / step;
  return int(complement ? all - on_step : on_step);
}

Expected<FrameRange> FrameRange::parse_unchecked(std::string_view text) {
  text = trim(text);
  // oiiotool's "A-BxN" (every Nth) and "A-ByN" (all but every Nth).
  if (const auto mark = text.find_first_of("xy"); mark != std::string_view::npos) {
    int step = 0;
    if (!parse_int(text.substr(mark + 1), step) || step < 1)
      return Error::usage("--frames '" + std::string(text) + "': after x or y comes the period N >= 1 (e.g. 0-47x3: every "
                          "third frame; 0-47y3: all but every third)");
    auto r = parse_unchecked(text.substr(0, mark));
    if (!r) return r;
    r->step = step;
    r->complement = text[mark] == 'y';
    if (r->count() == 0)
      return Error::usage("--frames " + std::string(text) + " selects no frame");
    return r;
  }
  // A leading '-' belongs to a negative first frame, so look for the separator after the first character.
  const auto dash = text.find('-', 1);
  FrameRange r;
  if (dash == std::string_view::npos) {
    if (!parse_int(text, r.first))
      return Error::usage("--frames '" + std::string(text) + "' is not a frame range: write A-B (e.g. 0-39) or A");
    r.last = r.first;
    return r;
  }
  if (!parse_int(trim(text.substr(0, dash)), r.first) || !parse_int(trim(text.substr(dash + 1)), r.last))
    return Error::usage("--frames '" + std::string(text) + "' is not a frame range: write A-B (e.g. 0-39) or A");
  if (r.last < r.first)
    return Error::usage("--frames " + std::string(text) + ": the last frame comes before the first; write A-B with A <= B");
  return r;
}

Expected<SequencePattern> SequencePattern::parse(std::string pattern) {
  SequencePattern p;
  p.pattern_ = pattern;
  // The placeholder is in the file name: a folder may contain '#' or '%'.
  const auto slash = pattern.rfind('/');
  const std::size_t name_start = slash == std::string::npos ? 0 : slash + 1;
  const auto hash = pattern.find('#', name_start);
  const auto pct = pattern.find('%', name_start);
  if (hash != std::string::npos) {
    auto end = pattern.find_first_not_of('#', hash);
    if (end == std::string::npos) end = pattern.size();
    if (pattern.find('#', end) != std::string::npos)
      return Error::usage("'" + shown(pattern) + "' has more than one run of '#': use one placeholder such as name.####.exr");
    // One '#' means one digit in Nuke but four in oiiotool (whose one digit is '@'): refused rather than guessed.
    if (end - hash == 1)
      return Error::usage("'" + shown(pattern) + "': a lone '#' is one digit in Nuke but four in oiiotool; write one '#' "
                          "per digit (name.####.exr for name.0012.exr) or %d for unpadded numbers");
    if (end - hash > 10)
      return Error::usage("'" + shown(pattern) + "': a placeholder of more than 10 '#' cannot be meant (frame numbers have at most 8 digits)");
    p.prefix_ = pattern.substr(0, hash);
    p.suffix_ = pattern.substr(end);
    p.width_ = int(end - hash);
    return p;
  }
  if (pct != std::string::npos) {
    // %d, %4d or %04d
    std::size_t i = pct + 1;
    int width = 0;
    while (i < pattern.size() && std::isdigit(static_cast<unsigned char>(pattern[i])) && width <= 100)
      width = width * 10 + (pattern[i++] - '0');
    if (i >= pattern.size() || pattern[i] != 'd')
      return Error::usage("'" + shown(pattern) + "': only %d or %0Nd placeholders are understood (or a run of '#')");
    if (width > 10)
      return Error::usage("'" + shown(pattern) + "': a placeholder wider than %010d cannot be meant (frame numbers have at most 8 digits)");
    p.prefix_ = pattern.substr(0, pct);
    p.suffix_ = pattern.substr(i + 1);
    p.width_ = width;
    if (p.suffix_.find('%') != std::string::npos)
      return Error::usage("'" + shown(pattern) + "' has more than one placeholder");
    return p;
  }
  p.prefix_ = pattern;
  return p;
}

namespace {
std::string padded(int frame, int width) {
  std::string digits = std::to_string(frame < 0 ? -frame : frame);
  if (int(digits.size()) < width) digits.insert(0, std::size_t(width) - digits.size(), '0');
  return (frame < 0 ? "-" : "") + digits;
}
}  // namespace

std::string frame_digits(int frame) { return padded(frame, 4); }

std::string SequencePattern::path(int frame) const {
  if (width_ < 0) return pattern_;
  return prefix_ + padded(frame, width_) + suffix_;
}

std::vector<int> SequencePattern::frames_on_disk() const {
  std::vector<int> frames;
  if (width_ < 0) return frames;
  namespace fs = std::filesystem;
  const fs::path prefix_path(prefix_);
  fs::path dir = prefix_path.parent_path();
  const std::string file_prefix = prefix_path.filename().string();
  const std::string& suffix = suffix_;
  std::error_code ec;
  if (dir.empty()) dir = ".";
  for (auto it = fs::directory_iterator(dir, ec); !ec && it != fs::directory_iterator(); it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.size() <= file_prefix.size() + suffix.size()) continue;
    if (name.compare(0, file_prefix.size(), file_prefix) != 0) continue;
    if (name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0) continue;
    const std::string_view digits(name.data() + file_prefix.size(), name.size() - file_prefix.size() - suffix.size());
    int frame = 0;
    if (!parse_int(digits, frame)) continue;
    // Only the spelling path(frame) gives: with `###`, color.0012.exr is not frame 12 (that is color.012.exr).
    if (digits != padded(frame, width_)) continue;
    frames.push_back(frame);
  }
  std::sort(frames.begin(), frames.end());
  frames.erase(std::unique(frames.begin(), frames.end()), frames.end());
  return frames;
}

namespace {
// A file of the pattern's folder with the pattern's prefix and suffix around digits of another width than the
// pattern's (`color.0000.exr` for `color.###.exr`): the likely meaning of a pattern that matches nothing. Empty when
// there is none.
std::string other_width_file(const SequencePattern& pattern) {
  namespace fs = std::filesystem;
  const fs::path prefix_path(pattern.prefix());
  const fs::path dir = prefix_path.parent_path().empty() ? fs::path(".") : prefix_path.parent_path();
  const std::string file_prefix = prefix_path.filename().string();
  const std::string& suffix = pattern.suffix();
  std::error_code ec;
  std::string best;
  for (auto it = fs::directory_iterator(dir, ec); !ec && it != fs::directory_iterator(); it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.size() <= file_prefix.size() + suffix.size() || name.compare(0, file_prefix.size(), file_prefix) != 0 ||
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
      continue;
    const std::string digits = name.substr(file_prefix.size(), name.size() - file_prefix.size() - suffix.size());
    if (digits.find_first_not_of("0123456789") != std::string::npos) continue;
    if (best.empty() || name < best) best = name;
  }
  return best.empty() ? best : (fs::path(pattern.prefix()).parent_path() / best).string();
}
}  // namespace

Expected<bool> input_exists(const std::string& path) {
  std::error_code ec;
  const bool found = std::filesystem::exists(path, ec);
  if (ec) return Error::input(path, "cannot be examined: " + ec.message());
  return found;
}

Expected<std::vector<int>> resolve_frames(const SequencePattern& pattern, const std::optional<FrameRange>& range) {
  std::vector<int> frames;
  if (!pattern.has_placeholder()) {
    auto found = input_exists(pattern.pattern());
    if (!found) return found.error();
    if (!*found)
      return Error::input(pattern.pattern(), "no such file (for a sequence, put #### or %04d where the frame number goes)");
    if (range) return range->frames();
    return std::vector<int>{0};
  }
  if (range) {
    for (int f : range->frames()) {
      auto found = input_exists(pattern.path(f));
      if (!found) return found.error();
      if (!*found)
        return Error::input(pattern.path(f), "missing: frame " + std::to_string(f) + " of --frames " +
                                                 std::to_string(range->first) + "-" + std::to_string(range->last) +
                                                 " does not exist; render it or narrow --frames");
      frames.push_back(f);
    }
    return frames;
  }
  frames = pattern.frames_on_disk();
  if (frames.empty()) {
    std::string hint = "check the folder and the number of # (their count is the zero-padded width)";
    if (const std::string other = other_width_file(pattern); !other.empty())
      hint = "there is " + other + ", numbered with another width: write one # per digit of its number";
    return Error::input(pattern.pattern(), "no frames found on disk matching this pattern; " + hint);
  }
  for (std::size_t i = 1; i < frames.size(); ++i) {
    if (frames[i] != frames[i - 1] + 1)
      return Error::input(pattern.path(frames[i - 1] + 1),
                          "missing: the sequence has a gap (frames " + std::to_string(frames.front()) + "-" +
                              std::to_string(frames[i - 1]) + " then " + std::to_string(frames[i]) +
                              "); render the missing frames or pick a contiguous range with --frames");
  }
  return frames;
}

Expected<std::vector<int>> parse_frame_list(std::string_view text) {
  std::set<int> frames;
  while (!text.empty()) {
    const auto comma = text.find(',');
    const std::string_view item = trim(text.substr(0, comma));
    if (!item.empty()) {
      auto range = FrameRange::parse(item);
      if (!range) return Error::usage("frame list '" + std::string(text) + "': " + range.error().message);
      if (range->count() > 10'000'000) return Error::usage("frame list item '" + std::string(item) + "' is too large");
      for (int f = range->first; f <= range->last; ++f) frames.insert(f);
    }
    if (comma == std::string_view::npos) break;
    text.remove_prefix(comma + 1);
  }
  return std::vector<int>(frames.begin(), frames.end());
}

}  // namespace temporal
