// Minimum and maximum of two floats as plain comparisons, for the per-pixel loops of the kernels. std::fmin /
// std::fmax honour NaN operands and are not inlined by GCC (a libm call per use, measured 11% of the PHLM frame);
// std::min / std::max take references, which keeps some loops from vectorising. Use these only where both operands
// are finite or where the NaN rule below is what you want: fast_min(a, b) returns a when either is NaN.
#pragma once

namespace temporal {

inline float fast_min(float a, float b) { return b < a ? b : a; }
inline float fast_max(float a, float b) { return a < b ? b : a; }

}  // namespace temporal
