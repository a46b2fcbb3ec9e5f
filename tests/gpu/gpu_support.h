// Shared by the GPU tests: one EGL context per test process (GTEST_SKIP when this machine has no EGL device; on
// CI and the development machine llvmpipe provides one, so the tests run), and the comparisons of a GPU output
// with its C++ reference.
#pragma once

#include "temporal/core/image.h"
#include "temporal/gpu/context.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

namespace temporal::test {

// The process's context, or null with the reason in `why`.
inline std::shared_ptr<gpu::Context> gpu_context(std::string* why) {
  static auto created = gpu::Context::create();
  if (!created) {
    *why = created.error().message;
    return nullptr;
  }
  return *created;
}

#define TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx)                                                 \
  std::string why_no_gpu_;                                                                \
  auto ctx = ::temporal::test::gpu_context(&why_no_gpu_);                                 \
  if (!ctx) GTEST_SKIP() << "no EGL device, GPU kernels not tested: " << why_no_gpu_

// Agreement of two planes: the largest absolute difference, the PSNR (peak 1, the display range of the test
// sequences), and the number of pixels where one is finite and the other not.
struct Agreement {
  double max_abs = 0.0;
  double psnr = INFINITY;
  std::size_t finiteness_mismatches = 0;

  // The worse of the two (over frames, channels or slots): the largest difference, the lowest PSNR, every mismatch.
  void merge(const Agreement& g) {
    max_abs = std::max(max_abs, g.max_abs);
    psnr = std::min(psnr, g.psnr);
    finiteness_mismatches += g.finiteness_mismatches;
  }
};

inline Agreement agreement(const float* a, const float* b, std::size_t n) {
  Agreement r;
  double sq = 0.0;
  std::size_t count = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (std::isfinite(a[i]) != std::isfinite(b[i])) {
      ++r.finiteness_mismatches;
      continue;
    }
    if (!std::isfinite(a[i])) continue;
    const double d = double(a[i]) - double(b[i]);
    r.max_abs = std::max(r.max_abs, std::abs(d));
    sq += d * d;
    ++count;
  }
  const double mse = count ? sq / double(count) : 0.0;
  r.psnr = mse > 0.0 ? 10.0 * std::log10(1.0 / mse) : INFINITY;
  return r;
}

// The worst agreement over the named channels of two images (a missing channel fails the test).
inline Agreement agreement(const Image& a, const Image& b, const std::vector<std::string>& channels) {
  Agreement worst;
  for (const auto& c : channels) {
    const float* pa = a.plane(c);
    const float* pb = b.plane(c);
    EXPECT_TRUE(pa && pb) << "channel " << c;
    if (!pa || !pb) return {INFINITY, 0.0, 0};
    const Agreement g = agreement(pa, pb, a.pixel_count());
    worst.merge(g);
  }
  return worst;
}

}  // namespace temporal::test
