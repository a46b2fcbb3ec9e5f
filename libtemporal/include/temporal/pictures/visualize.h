// Pictures of data: heat maps of per-pixel errors with a colour bar, and the G-buffer's depth, normals, motion and
// material ids (docs/conventions.md defines each layer). Every function maps values, nothing is tone mapped.
#pragma once

#include "temporal/core/error.h"
#include "temporal/pictures/colormap.h"
#include "temporal/pictures/picture.h"
#include "temporal/pictures/text.h"

#include <cstdint>
#include <string>

namespace temporal {

// A heat map: each value v shown as colormap_color(map, v, low, high); pixels where `invalid` is > 0.5 (a metric
// excluded them; may be null) in kInvalidColor, NaN in kNonFiniteColor.
Picture heat_map(const float* values, const float* invalid, int width, int height, Colormap map, float low, float high);

// A horizontal colour bar `width` pixels wide: the ramp from low to high with ticks and values at both ends and the
// middle, and `label` (e.g. "FLIP" or "|error| of luminance") under it.
Expected<Picture> colour_bar(Colormap map, float low, float high, const std::string& label, int width, const Font& font);

// `picture` with `bar` under it (both left-aligned, on white).
Picture stacked(const Picture& picture, const Picture& bar);

// The smallest of 1, 2, 2.5, 5 x 10^k that is >= v (a heat map's upper end a reader can read); 1 for v <= 0.
float nice_ceiling(float v);
// The q-quantile (0..1) of the finite values of a plane, by sorting a copy; 0 when there is none.
float plane_quantile(const float* values, std::size_t count, double q);

// Linear view depth (depth.Z): grey by inverse depth between the nearest and the farthest foreground pixel, near
// white, far dark; background (z >= 0.999 far_clip, or non-finite) black. far_clip <= 0: no background test.
Picture depth_picture(const float* z, int width, int height, float far_clip);
// World-space normals (N.X, N.Y, N.Z) as RGB = (N + 1) / 2; background (|N| < 0.5) black.
Picture normal_picture(const float* nx, const float* ny, const float* nz, int width, int height);
// Motion (motion.X, motion.Y): direction as hue (pointing right: red; up: yellow-green, by the HSV circle
// counter-clockwise with y up on screen), length as saturation, white for no motion, full saturation at
// `full_scale` pixels (<= 0: the frame's 99th percentile of the length, at least 1 pixel). Returns the scale used
// in `used_scale` when given.
Picture motion_picture(const float* mx, const float* my, int width, int height, float full_scale = 0.0f,
                       float* used_scale = nullptr);
// Material ids (uint `id`): a distinct colour per id (golden-ratio hues), background (0) black.
Picture id_picture(const std::uint32_t* id, int width, int height);
// HSV (h in degrees, s and v in [0, 1]) to 8-bit RGB.
Rgb8 hsv_color(float h, float s, float v);

}  // namespace temporal
