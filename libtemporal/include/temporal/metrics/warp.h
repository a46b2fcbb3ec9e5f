// Motion-compensated fetch of the previous frame (docs/conventions.md, "Motion vectors").
//
// motion.X/Y at pixel p are in pixels of the current image and point to where the surface seen at p was in the
// previous frame: p_prev = p + motion, with p the pixel centre (x + 0.5, y + 0.5) and y down.
#pragma once

#include <span>

namespace temporal {

// out(x, y) = previous sampled at p_prev = (x + 0.5 + motion_x, y + 0.5 + motion_y), bilinearly between the
// four nearest pixel centres (clamped to the edge pixels within half a pixel of the border). Where p_prev lies
// outside the image, [0, width) x [0, height), the surface was not visible in the previous frame and out is NaN,
// so that any metric that uses it drops the pixel. A NaN in `previous` propagates to the pixels that fetch it.
// All planes are width * height floats, row-major; parallel over rows. `motion_x` and `motion_y` null means
// no motion (out = previous).
void warp_bilinear(const float* previous, int width, int height, const float* motion_x, const float* motion_y,
                   float* out);

// The same fetch for several planes that share one motion field (e.g. the previous luminance of the reference
// and of every test): positions and weights are computed once per pixel. out[k] receives previous[k] warped.
void warp_bilinear(std::span<const float* const> previous, int width, int height, const float* motion_x,
                   const float* motion_y, std::span<float* const> out);

}  // namespace temporal
