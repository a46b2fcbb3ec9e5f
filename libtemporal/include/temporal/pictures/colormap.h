// Colour maps for heat maps of scalar images: FLIP maps in magma (as the FLIP paper, Andersson et al. 2020, and
// NVIDIA's tool show them), absolute errors in inferno or turbo, and viridis. Each is matplotlib's 256-entry
// table (sRGB display values); a value is shown as the entry round(255 t) of its position t in [0, 1] within
// the map's range, the indexing of NVIDIA's FLIP tool, so a FLIP map here looks like the tool's.
#pragma once

#include "temporal/core/error.h"
#include "temporal/pictures/picture.h"

#include <array>
#include <string>
#include <string_view>

namespace temporal {

enum class Colormap { Magma, Inferno, Viridis, Turbo, Grey };

// "magma", "inferno", "viridis", "turbo", "grey".
const char* colormap_name(Colormap map);
// The map called `name`; a Usage error listing the names otherwise.
Expected<Colormap> parse_colormap(std::string_view name);

// Entry `index` (0..255, clamped) of a map, as display values in [0, 1]: matplotlib 3.6's tables (grey: i / 255).
std::array<float, 3> colormap_entry(Colormap map, int index);

// The index a value takes: round(255 (v - low) / (high - low)), clamped to 0..255; -1 for a NaN value.
// high > low.
int colormap_index(float value, float low, float high);

// The 8-bit colour of a value: the entry of colormap_index, each component round(255 c); kNonFiniteColor for NaN.
Rgb8 colormap_color(Colormap map, float value, float low = 0.0f, float high = 1.0f);

}  // namespace temporal
