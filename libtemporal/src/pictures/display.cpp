// Display encoding through the OCIO config (temporal/pictures/display.h).
#include "temporal/pictures/display.h"

#include <algorithm>
#include <cmath>

namespace temporal {

Expected<DisplayEncoder> DisplayEncoder::create(const DisplayOptions& options) {
  if (!std::isfinite(options.exposure)) return Error::usage("--exposure must be a finite number of stops");
  auto config = ColorConfig::load(options.ocio);
  if (!config) return config.error();
  const auto spaces = config->color_spaces();
  if (std::find(spaces.begin(), spaces.end(), options.display) == spaces.end()) {
    std::string list;
    for (const auto& s : spaces) list += (list.empty() ? "" : ", ") + s;
    return Error::usage("--display '" + options.display + "' is not a colour space of the OCIO config " +
                        config->source() + " (it has: " + list + ")");
  }
  return DisplayEncoder(std::move(*config), options);
}

Expected<Picture> DisplayEncoder::encode(std::span<const float* const> planes, int width, int height) const {
  if (planes.empty() || width <= 0 || height <= 0) return Error::internal("DisplayEncoder::encode: nothing to encode");
  const std::size_t n = std::size_t(width) * std::size_t(height);
  const float gain = float(std::exp2(options_.exposure));
  static const std::string rgb[3] = {"R", "G", "B"};
  Image work(width, height);
  float* dst[3];
  for (int c = 0; c < 3; ++c) dst[c] = work.add_channel(rgb[c]);
  std::vector<std::uint8_t> bad(n, 0);
  for (int c = 0; c < 3; ++c) {
    // Grey for one plane; (c0, c1, 0) for two.
    const float* src = planes.size() == 1 ? planes[0] : (std::size_t(c) < planes.size() ? planes[std::size_t(c)] : nullptr);
    for (std::size_t i = 0; i < n; ++i) {
      const float v = src ? src[i] : 0.0f;
      if (!std::isfinite(v)) bad[i] = 1;
      dst[c][i] = std::isfinite(v) ? v * gain : 0.0f;
    }
  }
  if (auto st = config_.convert(work, rgb, colorspace::kSceneLinear, options_.display); !st) return st.error();
  Picture out(width, height);
  auto code = [](float v) { return std::uint8_t(std::lround(255.0f * std::clamp(std::isnan(v) ? 0.0f : v, 0.0f, 1.0f))); };
  for (int y = 0; y < height; ++y) {
    Rgb8* row = out.row(y);
    for (int x = 0; x < width; ++x) {
      const std::size_t i = std::size_t(y) * std::size_t(width) + std::size_t(x);
      row[x] = bad[i] ? kNonFiniteColor : Rgb8{code(dst[0][i]), code(dst[1][i]), code(dst[2][i])};
    }
  }
  return out;
}

Expected<Picture> DisplayEncoder::encode(const Image& image, std::span<const std::string> channels) const {
  std::vector<const float*> planes;
  for (const auto& c : channels) {
    const float* p = image.plane(c);
    if (!p) return Error::input({}, "no float channel '" + c + "' to show");
    planes.push_back(p);
  }
  return encode(planes, image.width(), image.height());
}

}  // namespace temporal
