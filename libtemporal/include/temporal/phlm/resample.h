// Motion-compensated history fetches for the temporal filters of `filter-phlm` (PHLM, TAA, EMA).
//
// Coordinates are in pixel-index space: the centre of pixel (x, y) is at (x, y) here (it is (x + 0.5, y + 0.5)
// in the image-space convention of docs/conventions.md). A history fetch for the current pixel (x, y) samples
// the previous frame at (x + motion.X, y + motion.Y): `motion` points from the current pixel to where its
// surface was in the previous frame, in pixels, jitter removed.
//
// Everything here is inline: the filters call it once per pixel inside their row loops.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace temporal::resample {

// True when the history position (pixel-index coordinates) lies on the previous image: its pixel-centre
// image position (fx + 0.5, fy + 0.5) is inside [0, width) x [0, height). Off-screen fetches reset histories.
inline bool on_screen(float fx, float fy, int width, int height) {
  return fx >= -0.5f && fy >= -0.5f && fx < float(width) - 0.5f && fy < float(height) - 0.5f;
}

// The four taps and weights of a bilinear fetch at (fx, fy), clamped to the image (edge texels repeat).
// Weights sum to 1; a fetch exactly at a pixel centre has weights (1, 0, 0, 0) and returns that pixel bit
// for bit, so a static scene (motion 0) reprojects histories exactly.
struct Bilinear {
  std::size_t i00, i10, i01, i11;  // plane offsets
  float w00, w10, w01, w11;

  template <typename T>
  float operator()(const T* plane) const {
    return w00 * float(plane[i00]) + w10 * float(plane[i10]) + w01 * float(plane[i01]) + w11 * float(plane[i11]);
  }
};

inline Bilinear bilinear(float fx, float fy, int width, int height) {
  const float x0f = std::floor(fx), y0f = std::floor(fy);
  const float tx = fx - x0f, ty = fy - y0f;
  const int x0 = std::clamp(int(x0f), 0, width - 1), x1 = std::clamp(int(x0f) + 1, 0, width - 1);
  const int y0 = std::clamp(int(y0f), 0, height - 1), y1 = std::clamp(int(y0f) + 1, 0, height - 1);
  const auto w = std::size_t(width);
  Bilinear b;
  b.i00 = std::size_t(y0) * w + std::size_t(x0);
  b.i10 = std::size_t(y0) * w + std::size_t(x1);
  b.i01 = std::size_t(y1) * w + std::size_t(x0);
  b.i11 = std::size_t(y1) * w + std::size_t(x1);
  b.w00 = (1.0f - tx) * (1.0f - ty);
  b.w10 = tx * (1.0f - ty);
  b.w01 = (1.0f - tx) * ty;
  b.w11 = tx * ty;
  return b;
}

// Index of the nearest pixel to (fx, fy), clamped to the image (for data that must not be blended: ids).
inline std::size_t nearest(float fx, float fy, int width, int height) {
  const int x = std::clamp(int(std::lround(fx)), 0, width - 1);
  const int y = std::clamp(int(std::lround(fy)), 0, height - 1);
  return std::size_t(y) * std::size_t(width) + std::size_t(x);
}

// Catmull-Rom cubic weights (tension 0.5, B = 0, C = 0.5 of Mitchell-Netravali) of the four taps at offsets
// -1, 0, 1, 2 from floor(f), for fraction t = f - floor(f). They sum to 1; two of them are negative for
// 0 < t < 1, so a Catmull-Rom fetch can overshoot the taps (TAA clips the result to the neighbourhood box).
inline void catmull_rom_weights(float t, float w[4]) {
  const float t2 = t * t, t3 = t2 * t;
  w[0] = 0.5f * (-t3 + 2.0f * t2 - t);
  w[1] = 0.5f * (3.0f * t3 - 5.0f * t2 + 2.0f);
  w[2] = 0.5f * (-3.0f * t3 + 4.0f * t2 + t);
  w[3] = 0.5f * (t3 - t2);
}

// A 4x4 Catmull-Rom fetch (Karis 2014, "history resampling") at (fx, fy) with clamped edges: taps and
// separable weights, shared by the channels of one pixel.
struct CatmullRom {
  std::size_t row[4];  // offsets of the four rows
  int col[4];          // the four columns
  float wx[4], wy[4];

  template <typename T>
  float operator()(const T* plane) const {
    float sum = 0.0f;
    for (int j = 0; j < 4; ++j) {
      const T* r = plane + row[j];
      const float h = wx[0] * float(r[col[0]]) + wx[1] * float(r[col[1]]) + wx[2] * float(r[col[2]]) +
                      wx[3] * float(r[col[3]]);
      sum += wy[j] * h;
    }
    return sum;
  }
};

inline CatmullRom catmull_rom(float fx, float fy, int width, int height) {
  const float x0f = std::floor(fx), y0f = std::floor(fy);
  CatmullRom c;
  catmull_rom_weights(fx - x0f, c.wx);
  catmull_rom_weights(fy - y0f, c.wy);
  const int x0 = int(x0f), y0 = int(y0f);
  for (int k = 0; k < 4; ++k) {
    c.col[k] = std::clamp(x0 - 1 + k, 0, width - 1);
    c.row[k] = std::size_t(std::clamp(y0 - 1 + k, 0, height - 1)) * std::size_t(width);
  }
  return c;
}

}  // namespace temporal::resample
