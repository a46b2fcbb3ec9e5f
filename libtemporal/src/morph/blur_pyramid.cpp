// Blur pyramid of seed 004 section 6: "a MIP map with a recursive 3-tap binomial weight filter ... read at a
// higher level using tri-cubic reconstruction". The paper blurs 8-bit tone-mapped RGB on the GPU; here the
// planes are float and the reconstruction is separable (a vertical 4-tap pass into one row of the level,
// then a horizontal 4-tap pass), so the cost per output pixel does not depend on the level.
#include "temporal/morph/blur_pyramid.h"

#include "temporal/core/parallel.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

namespace temporal::morph {

namespace {

// Uniform cubic B-spline weights for fraction f of the interval [i, i+1] (taps i-1 .. i+2). The B-spline
// is smooth (C2) and never overshoots, so the blurred layer has no ringing.
inline std::array<float, 4> bspline(float f) {
  const float f2 = f * f, f3 = f2 * f;
  return {(1.0f - f) * (1.0f - f) * (1.0f - f) / 6.0f, (3.0f * f3 - 6.0f * f2 + 4.0f) / 6.0f,
          (-3.0f * f3 + 3.0f * f2 + 3.0f * f + 1.0f) / 6.0f, f3 / 6.0f};
}

struct Taps {
  std::vector<int> index;    // 4 per output sample
  std::vector<float> weight;  // 4 per output sample
};

// Taps of level `level` (size n) for every full-resolution sample (blur_pyramid_taps).
Taps make_taps(int full, int n, int level) {
  Taps t;
  blur_pyramid_taps(full, n, level, t.index, t.weight);
  return t;
}

}  // namespace

// Level texel i sits at full-resolution pixel i * 2^level (see the header), so pixel x reads the level at
// u = x / 2^level.
void blur_pyramid_taps(int full, int n, int level, std::vector<int>& index, std::vector<float>& weight) {
  index.resize(std::size_t(full) * 4);
  weight.resize(std::size_t(full) * 4);
  const float scale = 1.0f / float(1 << level);
  for (int x = 0; x < full; ++x) {
    const float u = float(x) * scale;
    const int i0 = static_cast<int>(std::floor(u));
    const auto w = bspline(u - float(i0));
    for (int k = 0; k < 4; ++k) {
      index[std::size_t(x) * 4 + std::size_t(k)] = std::clamp(i0 - 1 + k, 0, n - 1);
      weight[std::size_t(x) * 4 + std::size_t(k)] = w[std::size_t(k)];
    }
  }
}

void BlurPyramid::build(std::span<const float* const> planes, int width, int height, int levels) {
  levels_ = std::max(levels, 0);
  channels_ = static_cast<int>(planes.size());
  base_.assign(planes.begin(), planes.end());
  widths_.assign(std::size_t(levels_) + 1, width);
  heights_.assign(std::size_t(levels_) + 1, height);
  data_.resize(std::size_t(levels_));
  for (int l = 1; l <= levels_; ++l) {
    widths_[l] = (widths_[l - 1] + 1) / 2;
    heights_[l] = (heights_[l - 1] + 1) / 2;
  }
  std::size_t scratch_size = 0;
  for (int l = 1; l <= levels_; ++l) scratch_size = std::max(scratch_size, std::size_t(widths_[l]) * heights_[l - 1]);
  scratch_.resize(scratch_size);
  for (int l = 1; l <= levels_; ++l) {
    const int pw = widths_[l - 1], ph = heights_[l - 1], lw = widths_[l], lh = heights_[l];
    auto& level = data_[std::size_t(l) - 1];
    level.resize(std::size_t(lw) * std::size_t(lh) * std::size_t(channels_));
    for (int c = 0; c < channels_; ++c) {
      const float* src = l == 1 ? base_[std::size_t(c)] : level_plane(l - 1, c);
      float* dst = level.data() + std::size_t(c) * std::size_t(lw) * std::size_t(lh);
      float* tmp = scratch_.data();
      // Horizontal [1 2 1]/4 at the even samples, edges clamped.
      parallel_rows(ph, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y) {
          const float* s = src + std::size_t(y) * std::size_t(pw);
          float* d = tmp + std::size_t(y) * std::size_t(lw);
          for (int i = 0; i < lw; ++i) {
            const int x = 2 * i;
            const float a = s[std::max(x - 1, 0)], b = s[x], cc = s[std::min(x + 1, pw - 1)];
            d[i] = 0.25f * a + 0.5f * b + 0.25f * cc;
          }
        }
      });
      // Vertical [1 2 1]/4 at the even rows.
      parallel_rows(lh, [&](int y0, int y1) {
        for (int j = y0; j < y1; ++j) {
          const int y = 2 * j;
          const float* a = tmp + std::size_t(std::max(y - 1, 0)) * std::size_t(lw);
          const float* b = tmp + std::size_t(y) * std::size_t(lw);
          const float* cc = tmp + std::size_t(std::min(y + 1, ph - 1)) * std::size_t(lw);
          float* d = dst + std::size_t(j) * std::size_t(lw);
          for (int i = 0; i < lw; ++i) d[i] = 0.25f * a[i] + 0.5f * b[i] + 0.25f * cc[i];
        }
      });
    }
  }
}

const float* BlurPyramid::level_plane(int level, int plane) const {
  if (level == 0) return base_[std::size_t(plane)];
  return data_[std::size_t(level) - 1].data() +
         std::size_t(plane) * std::size_t(widths_[level]) * std::size_t(heights_[level]);
}

void BlurPyramid::reconstruct_level(int level, float* const* out, float weight, bool accumulate) const {
  const int width = widths_[0], height = heights_[0];
  const int lw = widths_[level], lh = heights_[level];
  if (level == 0) {
    for (int c = 0; c < channels_; ++c) {
      parallel_rows(height, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y) {
          const float* s = base_[std::size_t(c)] + std::size_t(y) * std::size_t(width);
          float* d = out[c] + std::size_t(y) * std::size_t(width);
          for (int x = 0; x < width; ++x) d[x] = (accumulate ? d[x] : 0.0f) + weight * s[x];
        }
      });
    }
    return;
  }
  const Taps tx = make_taps(width, lw, level);
  const Taps ty = make_taps(height, lh, level);
  parallel_rows(height, [&](int y0, int y1) {
    std::vector<float> row(static_cast<std::size_t>(lw));  // one per band of rows, never per pixel
    for (int c = 0; c < channels_; ++c) {
      const float* src = level_plane(level, c);
      for (int y = y0; y < y1; ++y) {
        const int* yi = &ty.index[std::size_t(y) * 4];
        const float* yw = &ty.weight[std::size_t(y) * 4];
        const float* r0 = src + std::size_t(yi[0]) * std::size_t(lw);
        const float* r1 = src + std::size_t(yi[1]) * std::size_t(lw);
        const float* r2 = src + std::size_t(yi[2]) * std::size_t(lw);
        const float* r3 = src + std::size_t(yi[3]) * std::size_t(lw);
        for (int i = 0; i < lw; ++i) row[std::size_t(i)] = yw[0] * r0[i] + yw[1] * r1[i] + yw[2] * r2[i] + yw[3] * r3[i];
        float* d = out[c] + std::size_t(y) * std::size_t(width);
        const int* xi = tx.index.data();
        const float* xw = tx.weight.data();
        for (int x = 0; x < width; ++x) {
          const std::size_t k = std::size_t(x) * 4;
          const float v = xw[k] * row[std::size_t(xi[k])] + xw[k + 1] * row[std::size_t(xi[k + 1])] +
                          xw[k + 2] * row[std::size_t(xi[k + 2])] + xw[k + 3] * row[std::size_t(xi[k + 3])];
          d[x] = (accumulate ? d[x] : 0.0f) + weight * v;
        }
      }
    }
  }, 8);
}

void BlurPyramid::reconstruct(float level, std::span<float* const> out) const {
  level = std::clamp(level, 0.0f, float(levels_));
  const int l0 = static_cast<int>(std::floor(level));
  const float f = level - float(l0);
  if (f <= 0.0f || l0 >= levels_) {
    reconstruct_level(std::min(l0, levels_), out.data(), 1.0f, false);
    return;
  }
  // Cubic across levels: a smooth-step blend of the two neighbouring levels.
  const float w1 = f * f * (3.0f - 2.0f * f);
  reconstruct_level(l0, out.data(), 1.0f - w1, false);
  reconstruct_level(l0 + 1, out.data(), w1, true);
}

}  // namespace temporal::morph
