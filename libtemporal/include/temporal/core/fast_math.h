// Power functions for per-pixel loops that vectorise (FLIP's colour and feature maths in metrics/flip.cpp, the
// display gamma of morph's didyk method): std::pow and std::cbrt do not without -ffast-math, which the project
// avoids (NaN checks must keep working). Selects instead of branches, integer and float bits through
// std::bit_cast; the callers' sources are compiled with -fno-trapping-math so GCC may vectorise the selects.
// One copy for the library: morph had its own with a degree-6 exp2 (2.5e-7 relative against 1.0e-7 here, at the
// same speed in morph_benchmark).
//
// Accuracy on normal positive inputs, measured against double over every float of the reduced range: log2
// within 1.5e-7 absolute on [0.5, 2] (float rounding of the exponent's sum dominates further out), exp2 within
// 1.1e-7 relative on [-0.5, 0.5] (degree-7 polynomial); pow(x, p) within about 3e-6 relative for x in [1e-6, 1]
// and display exponents (2.2, 1/2.2, 2.4). FLIP's values are compared at 1e-4 (means) and 1/255 (maps), morph's
// display values are 8-bit at most: both far above that.
#pragma once

#include <bit>
#include <cstdint>

namespace temporal::fast_math {

// log2(x) for x > 0 and normal: exponent from the bits, mantissa m in [sqrt(1/2), sqrt(2)) through the series
// ln m = 2 atanh(t) = 2 (t + t^3/3 + t^5/5 + t^7/7 + t^9/9 + ...), t = (m - 1) / (m + 1), |t| <= 0.1716 (the
// first term left out, t^11/11, is below 4e-10).
inline float log2(float x) {
  std::uint32_t bits = std::bit_cast<std::uint32_t>(x);
  int e = int((bits >> 23) & 0xffu) - 127;
  bits = (bits & 0x007fffffu) | 0x3f800000u;
  float m = std::bit_cast<float>(bits);
  const bool high = m > 1.41421356f;
  m = high ? 0.5f * m : m;
  e += high ? 1 : 0;
  const float t = (m - 1.0f) / (m + 1.0f);
  const float t2 = t * t;
  const float s = t * (1.0f + t2 * (1.0f / 3.0f + t2 * (1.0f / 5.0f + t2 * (1.0f / 7.0f + t2 * (1.0f / 9.0f)))));
  return float(e) + 2.88539008f * s;  // 2 / ln 2
}

// 2^y for y in [-126, 127] (clamped): the integer part goes into the exponent bits, the fraction f in [-0.5,
// 0.5] through the Taylor polynomial of e^(f ln 2) to degree 7 (remainder below 6e-9).
inline float exp2(float y) {
  y = y > -126.0f ? y : -126.0f;
  y = y < 127.0f ? y : 127.0f;
  const std::int32_t biased = static_cast<std::int32_t>(y + 127.5f);  // > 0, so truncation rounds
  const float f = (y - float(biased - 127)) * 0.693147181f;
  const float p =
      1.0f +
      f * (1.0f + f * (0.5f + f * (1.0f / 6.0f + f * (1.0f / 24.0f + f * (1.0f / 120.0f + f * (1.0f / 720.0f + f * (1.0f / 5040.0f)))))));
  return p * std::bit_cast<float>(biased << 23);
}

// x^p for x > 0; for x <= 0 (and denormals): 1 when p == 0 (as std::pow(0, 0)), else 0. Callers pass p >= 0.
inline float pow(float x, float p) {
  const bool positive = x > 1e-30f;
  const float r = exp2(p * log2(positive ? x : 1.0f));  // both sides computed: no branch
  return positive ? r : (p == 0.0f ? 1.0f : 0.0f);
}

// t^(1/3) for t > 0 and normal, without a division: Newton's iteration on the inverse cube root,
// r <- r (4 - t r^3) / 3, whose relative error e becomes about -2 e^2 per step, from an estimate taken from the
// bits (the exponent divided by 3; error below 4%), then t^(1/3) = t r^2. Three steps: within 4e-7 relative
// (measured over [0.008, 1.3], CIELab's range). Inputs <= 0 give garbage, for callers that select it away.
inline float cbrt(float t) {
  float r = std::bit_cast<float>(0x54a21d2au - std::bit_cast<std::uint32_t>(t) / 3u);
  const float third = t * (1.0f / 3.0f);
  for (int i = 0; i < 3; ++i) r = r * ((4.0f / 3.0f) - third * (r * r * r));
  return t * r * r;
}

}  // namespace temporal::fast_math
