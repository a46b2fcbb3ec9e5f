#include "filter_common.h"

#include "temporal/core/color.h"
#include "temporal/core/parallel.h"

#include <algorithm>
#include <atomic>
#include <cmath>

namespace temporal::phlm {

Status validate_filter_input(const FilterInput& in) {
  if (!in.color || in.color->empty()) return Error::input({}, "empty input image");
  if (in.channels.size() != 1 && in.channels.size() != 3)
    return Error::usage("the filtered layer must have 1 or 3 channels (got " + std::to_string(in.channels.size()) +
                        "); pick one with --layer");
  for (const auto& c : in.channels)
    if (!in.color->plane(c)) return Error::input({}, "input has no float channel '" + c + "'");
  if ((in.motion_x == nullptr) != (in.motion_y == nullptr))
    return Error::internal("motion needs both motion.X and motion.Y");
  return Status::ok();
}

Expected<HistoryFetch> parse_history_fetch(const std::string& name, const char* flag) {
  if (name == "bilinear") return HistoryFetch::Bilinear;
  if (name == "catmull-rom") return HistoryFetch::CatmullRom;
  if (name == "nearest") return HistoryFetch::Nearest;
  return Error::usage(std::string(flag) + " '" + name + "' is not one of: bilinear, catmull-rom, nearest");
}

namespace detail {

std::size_t prepare_frame(const FilterInput& in, bool want_ycgco, std::vector<float> ycgco[3],
                          std::vector<std::uint8_t>& valid) {
  const Image& img = *in.color;
  const std::size_t n = img.pixel_count();
  const int w = img.width();
  const int channels = int(in.channels.size());
  if (valid.size() != n) valid.assign(n, 0);
  if (want_ycgco)
    for (int c = 0; c < 3; ++c)
      if (ycgco[c].size() != n) ycgco[c].assign(n, 0.0f);
  const float* p[3] = {};
  for (int c = 0; c < channels; ++c) p[c] = img.plane(in.channels[std::size_t(c)]);
  std::atomic<std::size_t> bad{0};
  parallel_rows(img.height(), [&](int y0, int y1) {
    std::size_t local = 0;
    for (std::size_t i = std::size_t(y0) * std::size_t(w); i < std::size_t(y1) * std::size_t(w); ++i) {
      bool ok = true;
      // NaN, Inf and magnitudes past kMaxSampleMagnitude are no sample (temporal/core/image.h, issue 26 item 12).
      for (int c = 0; c < channels; ++c) ok = ok && usable_sample(p[c][i]);
      valid[i] = ok ? 1 : 0;
      local += ok ? 0 : 1;
      if (want_ycgco) rgb_to_ycgco(p[0][i], p[1][i], p[2][i], ycgco[0][i], ycgco[1][i], ycgco[2][i]);
    }
    bad += local;
  });
  return bad.load();
}

void prepare_output(const FilterInput& in, Image& output, float* out[3]) {
  const Image& img = *in.color;
  if (output.width() != img.width() || output.height() != img.height()) output = Image(img.width(), img.height());
  for (std::size_t c = 0; c < in.channels.size(); ++c) out[c] = output.add_channel(in.channels[c]);
  output.metadata() = img.metadata();
}

const char* channel_suffix(int channels, int c) {
  static constexpr const char* kRgb[3] = {"R", "G", "B"};
  return channels == 3 ? kRgb[c] : "Y";
}

std::vector<std::string> history_channel_names(int channels) {
  std::vector<std::string> names;
  for (int c = 0; c < channels; ++c) names.push_back("history." + std::string(channel_suffix(channels, c)));
  return names;
}

void allocate_history(Image& history, Image& next, int channels, int width, int height) {
  history = Image(width, height);
  next = Image(width, height);
  for (const auto& n : history_channel_names(channels)) {
    history.add_channel(n);
    next.add_channel(n);
  }
}

Status load_history(const Image& state, int channels, const char* method, Image& history, Image& next) {
  if (channels != 1 && channels != 3)
    return Error::usage(std::string(method) + " state: the layer must have 1 or 3 channels");
  Image copy(state.width(), state.height()), fresh(state.width(), state.height());
  for (const auto& n : history_channel_names(channels)) {
    const float* src = state.plane(n);
    if (!src)
      return Error::input({}, "state has no channel '" + n + "': write it with `filter-phlm --method " + method +
                                  " --state-out`");
    if (count_non_finite({src, state.pixel_count()}) != 0)
      return Error::input({}, "state channel '" + n + "' holds NaN or Inf values");
    std::copy(src, src + state.pixel_count(), copy.add_channel(n));
    fresh.add_channel(n);
  }
  history = std::move(copy);
  next = std::move(fresh);
  return {};
}

}  // namespace detail
}  // namespace temporal::phlm
