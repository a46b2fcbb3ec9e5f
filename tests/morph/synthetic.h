// Synthetic frames for the morph tests: a procedural texture evaluated analytically, so the expected
// in-between image of a known motion is exact (no renderer needed).
#pragma once

#include "temporal/core/image.h"

#include <cmath>
#include <functional>

namespace temporal::test {

// Smooth texture in [0.1, 0.6] (wavelengths of ~9-14 px: resampling error stays small).
inline float texture(float x, float y, int c) {
  return 0.35f + 0.15f * std::sin(0.45f * x + 0.7f * float(c)) * std::cos(0.6f * y) + 0.1f * std::sin(0.3f * (x + y));
}

// Colour frame whose pixel (x, y) shows `f(x + 0.5, y + 0.5, channel)`.
inline Image make_color(int w, int h, const std::function<float(float, float, int)>& f) {
  Image img(w, h);
  const char* names[3] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c) {
    float* p = img.add_channel(names[c]);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) p[y * w + x] = f(float(x) + 0.5f, float(y) + 0.5f, c);
  }
  return img;
}

// G-buffer whose pixel (x, y) has motion m(x, y) and depth d(x, y).
inline Image make_gbuffer(int w, int h, const std::function<void(int, int, float&, float&, float&)>& f) {
  Image img(w, h);
  float* mx = img.add_channel("motion.X");
  float* my = img.add_channel("motion.Y");
  float* d = img.add_channel("depth.Z");
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) f(x, y, mx[y * w + x], my[y * w + x], d[y * w + x]);
  return img;
}

}  // namespace temporal::test
