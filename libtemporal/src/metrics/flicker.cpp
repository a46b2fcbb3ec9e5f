// Temporal instability against the reference (temporal/metrics/flicker.h; definition and choices in docs/compare.md).
#include "temporal/metrics/flicker.h"

#include "temporal/core/parallel.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace temporal {

double FlickerResult::rms() const { return pixels ? std::sqrt(sum_sq / double(pixels)) : 0.0; }
double FlickerResult::rms_inside() const { return pixels_inside ? std::sqrt(sum_sq_inside / double(pixels_inside)) : 0.0; }
double FlickerResult::rms_outside() const {
  return pixels_outside ? std::sqrt(sum_sq_outside / double(pixels_outside)) : 0.0;
}

void temporal_delta(const float* current, const float* previous_warped, std::size_t count, float* delta) {
  parallel_chunks(count, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) delta[i] = current[i] - previous_warped[i];
  });
}

FlickerResult flicker(const float* test_delta, const float* reference_delta, int width, int height,
                      const std::uint8_t* valid, const float* mask, float* map) {
  struct Row {
    double all = 0, inside = 0;
    std::size_t n = 0, n_in = 0;
  };
  std::vector<Row> rows(std::size_t(height > 0 ? height : 0));
  constexpr float kMax = std::numeric_limits<float>::max();
  parallel_rows(height, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
      const std::size_t o = std::size_t(y) * std::size_t(width);
      double all = 0, inside = 0;
      std::size_t n = 0, n_in = 0;
      for (int x = 0; x < width; ++x) {
        const std::size_t i = o + std::size_t(x);
        const float d = test_delta[i] - reference_delta[i];
        const bool ok = (!valid || valid[i]) && std::fabs(d) <= kMax;
        if (map) map[i] = ok ? std::fabs(d) : 0.0f;
        if (!ok) continue;
        const double d2 = double(d) * double(d);
        all += d2;
        ++n;
        if (mask && mask[i] > 0.5f) {
          inside += d2;
          ++n_in;
        }
      }
      rows[std::size_t(y)] = {all, inside, n, n_in};
    }
  });
  FlickerResult r;
  for (const auto& row : rows) {
    r.sum_sq += row.all;
    r.pixels += row.n;
    r.sum_sq_inside += row.inside;
    r.pixels_inside += row.n_in;
  }
  if (mask) {
    r.sum_sq_outside = std::max(0.0, r.sum_sq - r.sum_sq_inside);
    r.pixels_outside = r.pixels - r.pixels_inside;
  }
  return r;
}

}  // namespace temporal
