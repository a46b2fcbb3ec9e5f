// What a metric source file (src/compare/metric_<name>.cpp) includes: the registry's types. Each file defines
// `MetricDefinition <name>_metric()` for every metric it holds; registry.cpp declares and lists them in one line
// each. Private to the compare stage.
#pragma once

#include "temporal/compare/comparison.h"

#include "temporal/metrics/metrics.h"

#include <array>
#include <cmath>

namespace temporal {

// With --regions: PSNR over each region's valid pixels, from the squared error of every channel (the whole-frame
// psnr_db restricted to the region; docs/compare.md, "Regions"). NaN for an empty region.
inline std::array<double, kRegionCount> region_psnr(std::span<const float* const> test,
                                                    std::span<const float* const> reference, const FrameInputs& in) {
  std::array<SquaredError, kRegionCount> err{};
  const std::size_t n = std::size_t(in.width) * std::size_t(in.height);
  for (std::size_t i = 0; i < n; ++i) {
    if (!in.valid[i]) continue;
    double sum = 0.0;
    for (std::size_t c = 0; c < test.size(); ++c) {
      const double d = double(test[c][i]) - double(reference[c][i]);
      sum += d * d;
    }
    SquaredError& e = err[in.regions[i]];
    e.sum += sum;
    e.samples += test.size();
  }
  std::array<double, kRegionCount> out{};
  for (std::size_t r = 0; r < kRegionCount; ++r) out[r] = psnr_db(err[r], in.peak);
  return out;
}

}  // namespace temporal
