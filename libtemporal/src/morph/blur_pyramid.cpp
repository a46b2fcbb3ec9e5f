// Blur pyramid of seed 004 section 6: "a MIP map with a recursive 3-tap binomial weight filter ... read at a
// higher level using tri-cubic reconstruction". The paper blurs 8-bit tone-mapped RGB on the GPU; here the
// planes are float and the reconstruction is separable (a vertical 4-tap pass into one row of the level,
// then a horizontal 4-tap pass), so the cost per output pixel does not depend on the level.
#include "temporal/morph/blur_pyramid.h"

#include "temporal/core/isa.h"
#include "temporal/core/parallel.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <vector>

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

// The filter copies, one per instruction set (temporal/core/isa.h). v3 and v4 contract the weighted sums into FMAs
// (v2 has none): v2's pyramid and reconstruction differ from theirs in the last bits (tests/core/isa_test.cpp);
// v3 and v4 are bit-identical.
#define TEMPORAL_ISA_FILE "blur_pyramid_kernels.inc"
#include "temporal/core/isa_copies.inc"

void downsample_copy(const float* src, float* dst, float* tmp, int pw, int ph, int lw, int lh) {
  TEMPORAL_ISA_CALL(copy, return copy::downsample(src, dst, tmp, pw, ph, lw, lh))
}
void scale_plane_copy(const float* base, float* out, int width, int height, float weight, bool accumulate) {
  TEMPORAL_ISA_CALL(copy, return copy::scale_plane(base, out, width, height, weight, accumulate))
}
void reconstruct_planes_copy(const float* const* src_planes, int channels, int lw, int width, int height,
                             const Taps& tx, const Taps& ty, float* const* out, float weight, bool accumulate) {
  TEMPORAL_ISA_CALL(copy, return copy::reconstruct_planes(src_planes, channels, lw, width, height, tx, ty, out, weight,
                                                          accumulate))
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
      downsample_copy(src, dst, tmp, pw, ph, lw, lh);
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
    for (int c = 0; c < channels_; ++c)
      scale_plane_copy(base_[std::size_t(c)], out[c], width, height, weight, accumulate);
    return;
  }
  const Taps tx = make_taps(width, lw, level);
  const Taps ty = make_taps(height, lh, level);
  std::vector<const float*> planes(static_cast<std::size_t>(channels_));
  for (int c = 0; c < channels_; ++c) planes[std::size_t(c)] = level_plane(level, c);
  reconstruct_planes_copy(planes.data(), channels_, lw, width, height, tx, ty, out, weight, accumulate);
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
