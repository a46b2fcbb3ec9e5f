// Shared by the GPU tests: one EGL context per test process (GTEST_SKIP when this machine has no EGL device; on
// CI and the development machine llvmpipe provides one, so the tests run), and the comparisons of a GPU output
// with its C++ reference (agreement(), expect_within(), differing_values()).
#pragma once

#include "temporal/core/image.h"
#include "temporal/gpu/context.h"

#include <gtest/gtest.h>

#include <algorithm>
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
// sequences), the number of pixels where one is finite and the other not, and how many of the values differ by
// more than a bound (agreement()'s `beyond`; 0: any difference), for the tests that allow a few values past
// rounding (a decision flipped on a near tie) and bound their share.
struct Agreement {
  double max_abs = 0.0;
  double psnr = INFINITY;
  std::size_t finiteness_mismatches = 0;
  std::size_t values = 0;         // values compared
  std::size_t values_beyond = 0;  // ... of which |a - b| > beyond, or one finite and the other not

  // The worse of the two (over frames, channels or slots): the largest difference, the lowest PSNR, every mismatch.
  void merge(const Agreement& g) {
    max_abs = std::max(max_abs, g.max_abs);
    psnr = std::min(psnr, g.psnr);
    finiteness_mismatches += g.finiteness_mismatches;
    values += g.values;
    values_beyond += g.values_beyond;
  }
  double share_beyond() const { return values ? double(values_beyond) / double(values) : 0.0; }

  // The agreement of a comparison that could not run (a missing plane, a state that was not made): as bad as can
  // be, so that every bound fails.
  static Agreement failed() { return {INFINITY, 0.0, 0, 1, 1}; }
};

inline Agreement agreement(const float* a, const float* b, std::size_t n, double beyond = 0.0) {
  Agreement r;
  r.values = n;
  double sq = 0.0;
  std::size_t count = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (std::isfinite(a[i]) != std::isfinite(b[i])) {
      ++r.finiteness_mismatches;
      ++r.values_beyond;
      continue;
    }
    if (!std::isfinite(a[i])) continue;
    const double d = double(a[i]) - double(b[i]);
    r.max_abs = std::max(r.max_abs, std::abs(d));
    r.values_beyond += std::abs(d) > beyond;
    sq += d * d;
    ++count;
  }
  const double mse = count ? sq / double(count) : 0.0;
  r.psnr = mse > 0.0 ? 10.0 * std::log10(1.0 / mse) : INFINITY;
  return r;
}

// The worst agreement over the named channels of two images (a missing channel fails the test).
inline Agreement agreement(const Image& a, const Image& b, const std::vector<std::string>& channels,
                           double beyond = 0.0) {
  Agreement worst;
  for (const auto& c : channels) {
    const float* pa = a.plane(c);
    const float* pb = b.plane(c);
    EXPECT_TRUE(pa && pb) << "channel " << c;
    if (!pa || !pb) return Agreement::failed();
    worst.merge(agreement(pa, pb, a.pixel_count(), beyond));
  }
  return worst;
}

// The bounds every GPU test puts on a colour agreement: the largest difference, the lowest PSNR, and no pixel finite
// on one device only.
inline void expect_within(const Agreement& a, double max_abs, double min_psnr) {
  EXPECT_LE(a.max_abs, max_abs);
  EXPECT_GE(a.psnr, min_psnr);
  EXPECT_EQ(a.finiteness_mismatches, 0u);
}

// How many values of plane `name` differ between the two images at all (a decision: debug.disocclusion, a reset
// mask); a plane missing on either side fails the test.
inline std::size_t differing_values(const Image& a, const Image& b, const std::string& name) {
  const float* pa = a.plane(name);
  const float* pb = b.plane(name);
  EXPECT_TRUE(pa && pb) << name;
  if (!pa || !pb) return 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.pixel_count(); ++i) n += pa[i] != pb[i];
  return n;
}

}  // namespace temporal::test
