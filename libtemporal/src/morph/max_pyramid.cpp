// Max-MIP pyramid with argmax (seed 004 section 6, Figure 6). The paper packs the relative position of the
// maximum into 2 x 5 bits and the gradient into 6 bits of a 16-bit texel; on the CPU we keep the full float
// value and the absolute pixel index, which needs no quantisation and costs the same loop.
#include "temporal/morph/max_pyramid.h"

#include "temporal/core/parallel.h"

#include <algorithm>
#include <limits>

namespace temporal::morph {

namespace {
constexpr float kNone = -std::numeric_limits<float>::infinity();
}

void MaxPyramid::build(const float* values, int width, int height, int levels, int offset) {
  width_ = width;
  value_.resize(static_cast<std::size_t>(levels));
  index_.resize(static_cast<std::size_t>(levels));
  widths_.resize(static_cast<std::size_t>(levels));
  heights_.resize(static_cast<std::size_t>(levels));
  for (int l = 1; l <= levels; ++l) {
    const int size = 1 << l;
    const int lw = (width + offset + size - 1) / size;
    const int lh = (height + offset + size - 1) / size;
    widths_[l - 1] = lw;
    heights_[l - 1] = lh;
    auto& val = value_[l - 1];
    auto& idx = index_[l - 1];
    val.resize(std::size_t(lw) * std::size_t(lh));
    idx.resize(val.size());
    if (l == 1) {
      // Level 1 straight from the pixels (level 0 is never copied).
      parallel_rows(lh, [&](int y0, int y1) {
        for (int j = y0; j < y1; ++j) {
          for (int i = 0; i < lw; ++i) {
            float best = kNone;
            std::int32_t where = -1;
            for (int dy = 0; dy < 2; ++dy) {
              const int y = 2 * j + dy - offset;
              if (y < 0 || y >= height) continue;
              for (int dx = 0; dx < 2; ++dx) {
                const int x = 2 * i + dx - offset;
                if (x < 0 || x >= width) continue;
                const float v = values[std::size_t(y) * std::size_t(width) + std::size_t(x)];
                if (v > best || where < 0) {
                  best = v;
                  where = y * width + x;
                }
              }
            }
            val[std::size_t(j) * std::size_t(lw) + std::size_t(i)] = best;
            idx[std::size_t(j) * std::size_t(lw) + std::size_t(i)] = where;
          }
        }
      });
    } else {
      // Level l from the 2x2 children of level l-1: copy the whole entry of the largest (Figure 6).
      const auto& pv = value_[l - 2];
      const auto& pi = index_[l - 2];
      const int pw = widths_[l - 2];
      const int ph = heights_[l - 2];
      parallel_rows(lh, [&](int y0, int y1) {
        for (int j = y0; j < y1; ++j) {
          for (int i = 0; i < lw; ++i) {
            float best = kNone;
            std::int32_t where = -1;
            for (int dy = 0; dy < 2; ++dy) {
              const int cy = 2 * j + dy;
              if (cy >= ph) continue;
              for (int dx = 0; dx < 2; ++dx) {
                const int cx = 2 * i + dx;
                if (cx >= pw) continue;
                const std::size_t c = std::size_t(cy) * std::size_t(pw) + std::size_t(cx);
                if (pi[c] >= 0 && (pv[c] > best || where < 0)) {
                  best = pv[c];
                  where = pi[c];
                }
              }
            }
            val[std::size_t(j) * std::size_t(lw) + std::size_t(i)] = best;
            idx[std::size_t(j) * std::size_t(lw) + std::size_t(i)] = where;
          }
        }
      });
    }
  }
}

MaxPyramid::Entry MaxPyramid::at(int level, int i, int j) const {
  Entry e;
  if (level < 1 || level > levels()) return e;
  const int lw = widths_[level - 1];
  const int lh = heights_[level - 1];
  if (i < 0 || j < 0 || i >= lw || j >= lh) return e;
  const std::size_t k = std::size_t(j) * std::size_t(lw) + std::size_t(i);
  e.value = value_[level - 1][k];
  const std::int32_t where = index_[level - 1][k];
  if (where >= 0) {
    e.x = where % width_;
    e.y = where / width_;
  } else {
    e.value = kNone;
  }
  return e;
}

}  // namespace temporal::morph
