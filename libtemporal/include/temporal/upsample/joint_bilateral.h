// Geometry-aware (joint-bilateral) upsampling of a jittered low-resolution payload: seed 000 (Herzog et al.
// 2010, "Spatio-Temporal Upsampling on the GPU") section 3.1, equations 1-3.
//
// The low-resolution image l is 1/k of the full resolution per axis and was shaded under the regular jitter
// pattern of docs/conventions.md: low-resolution pixel (x, y) of a frame with sub-pixel (sx, sy) is exactly
// full-resolution pixel (k x + sx, k y + sy). Its geometry (normal, depth) is therefore read from the
// full-resolution G-buffer at that pixel. A full-resolution pixel i takes the four nearest low-resolution
// samples N{i} (two per axis) and weights each with
//     w_s(i, j) = n(max(0, 1 - n_i . n_j)^2, sigma_n^2) * d(|z_i - z_j|^2, sigma_d^2) * k(i, j)     (eq. 2)
// where n = d = g(., ., 3) is the tri-weight kernel of eq. 3 and k is an image-space kernel: a hat (bilinear)
// function for the spatial method, g(distance, r, gamma) for the spatio-temporal method (section 3.3).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace temporal::upsample {

// Clamp of eq. 3: "clamped at a small epsilon which avoids zero weights". The paper gives no value; 1e-3
// keeps the product of three kernels (n * d * k, up to a power of 4) above FLT_MIN (1e-3^10 = 1e-30).
inline constexpr float kKernelEpsilon = 1e-3f;
// Published defaults (seed 000 section 3.1).
inline constexpr float kSigmaNormal = 0.2f;         // sigma_n
inline constexpr float kSigmaDepthFraction = 0.03f;  // sigma_d = 3% of (far - near)
inline constexpr float kTriWeightGamma = 3.0f;       // gamma of n and d: the tri-weight kernel

// Eq. 3: g(x, sigma, gamma) = max(eps, 1 - x / sigma)^gamma. Dimensionless; x and sigma in the same units.
inline float kernel_g(float x, float sigma, float gamma, float eps = kKernelEpsilon) {
  return std::pow(std::max(eps, 1.0f - x / sigma), gamma);
}

// The tri-weight kernel g(x^2, sigma^2, 3) with the cube written out (the per-pixel form).
inline float tri_weight(float x, float sigma, float eps = kKernelEpsilon) {
  const float t = std::max(eps, 1.0f - (x * x) / (sigma * sigma));
  return t * t * t;
}

// Normal term of eq. 2: n(max(0, 1 - n_i . n_j)^2, sigma_n^2) with n = tri-weight. `dot` is n_i . n_j of
// unit normals.
inline float normal_weight(float dot, float sigma_n = kSigmaNormal) {
  return tri_weight(std::max(0.0f, 1.0f - dot), sigma_n);
}

// Depth term of eq. 2: d(|z_i - z_j|^2, sigma_d^2) with d = tri-weight. Depths and sigma_d in world units
// (linear view depth).
inline float depth_weight(float z_i, float z_j, float sigma_d) { return tri_weight(z_i - z_j, sigma_d); }

// Eq. 2's geometric factor n * d of one sample in the per-pixel form every joint-bilateral kernel of the stage
// runs (spatial, temporal's hole filling, herzog's eq. 6): both tri-weights of eq. 3 with 1 / sigma^2
// precomputed, multiplied out in one expression. `dot` = n_i . n_j, `dz` = z_i - z_j (world units),
// inv_sn2 = 1 / sigma_n^2, inv_sd2 = 1 / sigma_d^2. Equals normal_weight(dot, sigma_n) * depth_weight(z_i, z_j,
// sigma_d) up to float rounding (tests/upsample/equations_test.cpp); NaN geometry gives NaN (callers drop it).
inline float geometric_weight(float dot, float dz, float inv_sn2, float inv_sd2) {
  const float xn = std::max(0.0f, 1.0f - dot);
  const float tn = std::max(kKernelEpsilon, 1.0f - xn * xn * inv_sn2);
  const float td = std::max(kKernelEpsilon, 1.0f - dz * dz * inv_sd2);
  return tn * tn * tn * td * td * td;
}

// Image-space kernel of the spatio-temporal method (section 3.3): k(i, j) = g(|x(i) - x(j)|, r, gamma) with
// r the low-resolution pixel diagonal in full-resolution pixels (r = k * sqrt(2)).
inline float image_kernel(float distance_px, float r, float gamma) { return kernel_g(distance_px, r, gamma); }

// Hat (bilinear) kernel of the spatial method: offsets (dx, dy) in full-resolution pixels from the sample,
// |dx|, |dy| <= k.
inline float hat_kernel(float dx, float dy, int k) {
  return std::max(0.0f, 1.0f - std::abs(dx) / float(k)) * std::max(0.0f, 1.0f - std::abs(dy) / float(k));
}

// Position of the regular jitter pattern: sub-pixel (sx, sy) of a k x k low-resolution pixel.
struct JitterGrid {
  int k = 1;   // factor: full = k * low per axis
  int sx = 0;  // 0 .. k-1
  int sy = 0;  // 0 .. k-1
  // Index of the nearest low-resolution sample at or left of full-resolution coordinate X (may be -1 at the
  // left border), and the offset X - (k * x0 + sx) in 0 .. k-1.
  int tap0_x(int X) const { return floor_div(X - sx, k); }
  int tap0_y(int Y) const { return floor_div(Y - sy, k); }
  bool computed(int X, int Y) const { return floor_mod(X - sx, k) == 0 && floor_mod(Y - sy, k) == 0; }
  static int floor_div(int a, int b) { return (a >= 0) ? a / b : -((-a + b - 1) / b); }
  static int floor_mod(int a, int b) { return a - b * floor_div(a, b); }
};

}  // namespace temporal::upsample
