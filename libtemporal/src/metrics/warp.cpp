// Motion-compensated bilinear fetch (temporal/metrics/warp.h), following docs/conventions.md: p_prev = p + motion.
#include "temporal/metrics/warp.h"

#include "temporal/core/parallel.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

namespace temporal {

void warp_bilinear(std::span<const float* const> previous, int width, int height, const float* motion_x,
                   const float* motion_y, std::span<float* const> out) {
  const std::size_t n = std::size_t(width) * std::size_t(height);
  const std::size_t planes = std::min(previous.size(), out.size());
  if (!motion_x || !motion_y) {
    for (std::size_t k = 0; k < planes; ++k) std::copy(previous[k], previous[k] + n, out[k]);
    return;
  }
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float fw = float(width), fh = float(height);
  parallel_rows(height, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
      const std::size_t row = std::size_t(y) * std::size_t(width);
      for (int x = 0; x < width; ++x) {
        const std::size_t i = row + std::size_t(x);
        // Position in the previous image, in pixel-area coordinates (pixel centres at k + 0.5).
        const float px = float(x) + 0.5f + motion_x[i];
        const float py = float(y) + 0.5f + motion_y[i];
        if (!(px >= 0.0f && px < fw && py >= 0.0f && py < fh)) {  // also rejects NaN motion
          for (std::size_t k = 0; k < planes; ++k) out[k][i] = nan;
          continue;
        }
        // Bilinear between the centres around p_prev; within half a pixel of the border, clamp to the edge.
        const float u = std::clamp(px - 0.5f, 0.0f, fw - 1.0f);
        const float v = std::clamp(py - 0.5f, 0.0f, fh - 1.0f);
        const int x0 = std::min(int(u), width - 1), y0p = std::min(int(v), height - 1);
        const int x1 = std::min(x0 + 1, width - 1), y1p = std::min(y0p + 1, height - 1);
        const float fx = u - float(x0), fy = v - float(y0p);
        const std::size_t i00 = std::size_t(y0p) * std::size_t(width) + std::size_t(x0);
        const std::size_t i01 = std::size_t(y0p) * std::size_t(width) + std::size_t(x1);
        const std::size_t i10 = std::size_t(y1p) * std::size_t(width) + std::size_t(x0);
        const std::size_t i11 = std::size_t(y1p) * std::size_t(width) + std::size_t(x1);
        for (std::size_t k = 0; k < planes; ++k) {
          const float* p = previous[k];
          const float top = p[i00] + fx * (p[i01] - p[i00]);
          const float bottom = p[i10] + fx * (p[i11] - p[i10]);
          out[k][i] = top + fy * (bottom - top);
        }
      }
    }
  });
}

void warp_bilinear(const float* previous, int width, int height, const float* motion_x, const float* motion_y,
                   float* out) {
  warp_bilinear(std::span<const float* const>(&previous, 1), width, height, motion_x, motion_y,
                std::span<float* const>(&out, 1));
}

}  // namespace temporal
