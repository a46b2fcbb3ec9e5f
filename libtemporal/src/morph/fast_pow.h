// Vectorisable (with -fno-trapping-math, set on the morph sources) power function for the per-pixel gamma work of the morph module (encode to display values,
// eq. for H'), about 1e-6 relative error on positive finite inputs. std::pow is ~10x slower and does not
// vectorise without -ffast-math, which the project avoids (NaN checks must keep working).
#pragma once

#include <bit>
#include <cstdint>

namespace temporal::morph::detail {

// log2(x) for x > 0 (normal floats): exponent from the bits, mantissa m in [sqrt(1/2), sqrt(2)) through the
// atanh series 2/ln2 * (t + t^3/3 + t^5/5 + t^7/7 + t^9/9), t = (m-1)/(m+1), |t| <= 0.172.
inline float fast_log2(float x) {
  std::uint32_t bits = std::bit_cast<std::uint32_t>(x);
  int e = int((bits >> 23) & 0xff) - 127;
  bits = (bits & 0x007fffffu) | 0x3f800000u;  // mantissa in [1, 2)
  float m = std::bit_cast<float>(bits);
  const bool high = m > 1.41421356f;  // selects, not branches: the loops calling this vectorise
  m = high ? 0.5f * m : m;
  e += high ? 1 : 0;
  const float t = (m - 1.0f) / (m + 1.0f);
  const float t2 = t * t;
  const float s = t * (1.0f + t2 * (1.0f / 3.0f + t2 * (1.0f / 5.0f + t2 * (1.0f / 7.0f + t2 * (1.0f / 9.0f)))));
  return float(e) + 2.88539008f * s;  // 2 / ln 2
}

// 2^y: integer part into the exponent bits, fraction in [-0.5, 0.5] through a degree-6 Taylor polynomial.
inline float fast_exp2(float y) {
  y = y > -126.0f ? y : -126.0f;
  y = y < 127.0f ? y : 127.0f;
  const std::int32_t biased = static_cast<std::int32_t>(y + 127.5f);  // > 0, so truncation rounds
  const float fi = float(biased - 127);
  const float f = (y - fi) * 0.69314718f;
  const float p =
      1.0f + f * (1.0f + f * (0.5f + f * (1.0f / 6.0f + f * (1.0f / 24.0f + f * (1.0f / 120.0f + f * (1.0f / 720.0f))))));
  return p * std::bit_cast<float>(biased << 23);
}

// x^p for x > 0; 0 for x <= 0 (display values are never negative).
inline float fast_pow(float x, float p) {
  const float r = fast_exp2(p * fast_log2(x > 1e-30f ? x : 1.0f));  // both sides computed: no branch
  return x > 1e-30f ? r : 0.0f;
}

}  // namespace temporal::morph::detail
