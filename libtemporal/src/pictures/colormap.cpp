// Colour maps (temporal/pictures/colormap.h).
#include "temporal/pictures/colormap.h"

#include "colormap_tables.h"

#include <cmath>

namespace temporal {

const char* colormap_name(Colormap map) {
  switch (map) {
    case Colormap::Magma: return "magma";
    case Colormap::Inferno: return "inferno";
    case Colormap::Viridis: return "viridis";
    case Colormap::Turbo: return "turbo";
    case Colormap::Grey: return "grey";
  }
  return "magma";
}

Expected<Colormap> parse_colormap(std::string_view name) {
  for (Colormap m : {Colormap::Magma, Colormap::Inferno, Colormap::Viridis, Colormap::Turbo, Colormap::Grey})
    if (name == colormap_name(m)) return m;
  return Error::usage("no colour map '" + std::string(name) + "': use magma, inferno, viridis, turbo or grey");
}

std::array<float, 3> colormap_entry(Colormap map, int index) {
  index = index < 0 ? 0 : index > 255 ? 255 : index;
  const float (*table)[3] = nullptr;
  switch (map) {
    case Colormap::Magma: table = colormap_tables::magma; break;
    case Colormap::Inferno: table = colormap_tables::inferno; break;
    case Colormap::Viridis: table = colormap_tables::viridis; break;
    case Colormap::Turbo: table = colormap_tables::turbo; break;
    case Colormap::Grey: {
      const float v = float(index) / 255.0f;
      return {v, v, v};
    }
  }
  return {table[index][0], table[index][1], table[index][2]};
}

int colormap_index(float value, float low, float high) {
  if (std::isnan(value)) return -1;
  const float t = (value - low) / (high - low);
  if (!(t > 0.0f)) return 0;
  if (t >= 1.0f) return 255;
  return int(std::lround(255.0f * t));
}

Rgb8 colormap_color(Colormap map, float value, float low, float high) {
  const int index = colormap_index(value, low, high);
  if (index < 0) return kNonFiniteColor;
  const auto c = colormap_entry(map, index);
  auto code = [](float v) { return std::uint8_t(std::lround(255.0f * v)); };
  return {code(c[0]), code(c[1]), code(c[2])};
}

}  // namespace temporal
