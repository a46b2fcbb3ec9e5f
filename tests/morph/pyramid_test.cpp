// Max-pyramid with argmax (seed 004 Figure 6) and the 3-tap binomial blur pyramid.
#include "temporal/morph/blur_pyramid.h"
#include "temporal/morph/max_pyramid.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace temporal::morph {
namespace {

TEST(MaxPyramid, MatchesBruteForceMaximumAndPositionWithOffsetBlocks) {
  const int w = 45, h = 30, levels = 3, offset = 4;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> dist(0.0f, 100.0f);
  std::vector<float> v(std::size_t(w) * h);
  for (auto& x : v) x = dist(rng);
  MaxPyramid p;
  p.build(v.data(), w, h, levels, offset);
  for (int l = 1; l <= levels; ++l) {
    const int s = 1 << l;
    for (int j = 0; j < p.level_height(l); ++j) {
      for (int i = 0; i < p.level_width(l); ++i) {
        float best = -std::numeric_limits<float>::infinity();
        int bx = -1, by = -1;
        for (int y = j * s - offset; y < (j + 1) * s - offset; ++y)
          for (int x = i * s - offset; x < (i + 1) * s - offset; ++x)
            if (x >= 0 && y >= 0 && x < w && y < h && v[std::size_t(y) * w + x] > best) {
              best = v[std::size_t(y) * w + x];
              bx = x;
              by = y;
            }
        const auto e = p.at(l, i, j);
        ASSERT_EQ(e.x, bx) << "level " << l << " texel " << i << "," << j;
        ASSERT_EQ(e.y, by);
        if (bx >= 0) {
          ASSERT_EQ(e.value, best);
        }
      }
    }
  }
}

TEST(BlurPyramid, PreservesConstantsAndLinearRampsAwayFromBorders) {
  const int w = 64, h = 48;
  std::vector<float> c(std::size_t(w) * h, 0.25f), ramp(std::size_t(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) ramp[std::size_t(y) * w + x] = 0.01f * float(x) + 0.02f * float(y);
  const float* in[2] = {c.data(), ramp.data()};
  BlurPyramid p;
  p.build(in, w, h, 3);
  ASSERT_EQ(p.level_width(1), 32);
  ASSERT_EQ(p.level_width(3), 8);
  for (float level : {1.0f, 2.0f, 2.5f}) {
    std::vector<float> a(c.size()), b(c.size());
    float* out[2] = {a.data(), b.data()};
    p.reconstruct(level, out);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        ASSERT_NEAR(a[std::size_t(y) * w + x], 0.25f, 1e-5f);
        // The binomial filter and the cubic B-spline both reproduce linear functions: no shift, no gain.
        if (x >= 16 && y >= 16 && x < w - 16 && y < h - 16) {
          ASSERT_NEAR(b[std::size_t(y) * w + x], ramp[std::size_t(y) * w + x], 1e-4f) << "level " << level;
        }
      }
  }
}

TEST(BlurPyramid, BlursAnImpulseIntoASymmetricNormalisedKernel) {
  const int w = 64, h = 64;
  std::vector<float> img(std::size_t(w) * h, 0.0f);
  img[std::size_t(32) * w + 32] = 1.0f;
  const float* in[1] = {img.data()};
  BlurPyramid p;
  p.build(in, w, h, 2);
  std::vector<float> out(img.size());
  float* o[1] = {out.data()};
  p.reconstruct(2.0f, o);
  double sum = 0.0, mx = 0.0, var = 0.0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double v = out[std::size_t(y) * w + x];
      sum += v;
      mx += v * x;
      var += v * (x - 32) * (x - 32);
    }
  // Energy: one impulse spreads to 16 pixels per level-2 texel, so the blurred sum is 1 (the level-2 grid
  // has one sample per 4x4 pixels and reconstruction interpolates them back to every pixel).
  EXPECT_NEAR(sum, 1.0, 1e-3);
  EXPECT_NEAR(mx / sum, 32.0, 1e-3);  // centred: no half-pixel shift
  // An impulse on a level-2 texel centre reaches that texel only (the binomial taps of its odd neighbours
  // are decimated away), so the spread is the cubic B-spline's at spacing 4: variance 4^2 / 3 px^2.
  EXPECT_NEAR(var / sum, 16.0 / 3.0, 0.05);
  // The peak is lower than the impulse: it is blurred.
  EXPECT_LT(out[std::size_t(32) * w + 32], 0.1f);
}

}  // namespace
}  // namespace temporal::morph
