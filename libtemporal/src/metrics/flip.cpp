// FLIP and HDR-FLIP (temporal/metrics/flip.h). The header gives the definitions and the paper steps; this file
// explains the implementation choices.
//
// Layout of the work, per image: (1) a point-wise pass to YyCxCz (exposure and tone mapping for HDR-FLIP,
// sRGB decoding for LDR inputs); (2) one horizontal pass that runs all seven 1-D filters a row needs (CSF of Y,
// Cx, the two Gaussians of Cz, and the feature Gaussian with its two derivatives), reading each input row once;
// (3) one vertical pass that finishes the seven 2-D filters and turns them, still in registers, into the five
// per-pixel quantities the comparison needs (Hunt-adjusted CIELab and the edge and point magnitudes). The test
// and the reference go through (1)-(3) separately, so a reference could be kept for several tests; (4) a
// point-wise pass combines the two into the FLIP map. All passes are parallel over rows with unit-stride
// inner loops over x; the filters work on strips of kStrip pixels so their accumulators stay in registers.
#include "temporal/metrics/flip.h"

#include "fast_math.h"
#include "temporal/core/parallel.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

namespace temporal {
namespace flip {
namespace {

// D65 white of the reference's colour transforms, and its inverse (the reference's constants, 9 digits).
constexpr Color kWhite = {0.950428545f, 1.0f, 1.088900371f};
constexpr Color kInvWhite = {1.052156925f, 1.0f, 0.918357670f};
// Linear Rec.709 -> XYZ: the exact rationals of the sRGB primaries and D65 white, as the reference has them.
constexpr float kRgbToXyz[9] = {10135552.0f / 24577794.0f, 8788810.0f / 24577794.0f, 4435075.0f / 24577794.0f,
                                2613072.0f / 12288897.0f,  8788810.0f / 12288897.0f, 887015.0f / 12288897.0f,
                                1425312.0f / 73733382.0f,  8788810.0f / 73733382.0f, 70074185.0f / 73733382.0f};
constexpr float kXyzToRgb[9] = {3.241003275f,  -1.537398934f, -0.498615861f, -0.969224334f, 1.875930071f,
                                0.041554224f,  0.055639423f,  -0.204011202f, 1.057148933f};
// CIELab's piecewise cube root: t^(1/3) above (6/29)^3, t / (3 (6/29)^2) + 4/29 below.
constexpr float kLabDelta = 6.0f / 29.0f;
constexpr float kLabDeltaCube = kLabDelta * kLabDelta * kLabDelta;
constexpr float kLabFactor = 1.0f / (3.0f * kLabDelta * kLabDelta);
constexpr float kLabTerm = 4.0f / 29.0f;
constexpr float kPi = 3.14159265358979f;  // the reference's float pi (filter sizes depend on its rounding)

// The tone mappers as rational functions (c^2 k0 + c k1 + k2) / (c^2 k3 + c k4 + k5), per channel; Reinhard
// is handled apart (it divides by the luminance). ACES: Narkowicz's fit with the 0.6 pre-exposure cancelled.
constexpr float kAces[6] = {0.6f * 0.6f * 2.51f, 0.6f * 0.03f, 0.0f, 0.6f * 0.6f * 2.43f, 0.6f * 0.59f, 0.14f};
constexpr float kHable[6] = {0.231683f, 0.013791f, 0.0f, 0.18f, 0.3f, 0.018f};
const float* rational_coefficients(FlipToneMapper t) { return t == FlipToneMapper::Hable ? kHable : kAces; }

inline float clamp01(float v) { return std::min(std::max(v, 0.0f), 1.0f); }

// CIELab from XYZ with a given cube root: the scalar API uses std::pow, the pixel loops fast_math::pow.
template <typename Pow>
inline Color lab_from_xyz(float x, float y, float z, Pow pow) {
  auto f = [&](float t) { return t > kLabDeltaCube ? pow(t, 1.0f / 3.0f) : kLabFactor * t + kLabTerm; };
  const float fx = f(x * kInvWhite[0]), fy = f(y * kInvWhite[1]), fz = f(z * kInvWhite[2]);
  return {116.0f * fy - 16.0f, 500.0f * (fx - fy), 200.0f * (fy - fz)};
}

inline float std_pow(float x, float p) { return std::pow(x, p); }

float color_max_distance() {
  const Color green = hunt_adjust(xyz_to_lab(linear_rgb_to_xyz({0.0f, 1.0f, 0.0f})));
  const Color blue = hunt_adjust(xyz_to_lab(linear_rgb_to_xyz({0.0f, 0.0f, 1.0f})));
  return std::pow(hyab(green, blue), kQc);
}

}  // namespace

float srgb_to_linear(float c) { return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f); }

Color linear_rgb_to_xyz(const Color& c) {
  const float* m = kRgbToXyz;
  return {m[0] * c[0] + m[1] * c[1] + m[2] * c[2], m[3] * c[0] + m[4] * c[1] + m[5] * c[2],
          m[6] * c[0] + m[7] * c[1] + m[8] * c[2]};
}

Color xyz_to_linear_rgb(const Color& c) {
  const float* m = kXyzToRgb;
  return {m[0] * c[0] + m[1] * c[1] + m[2] * c[2], m[3] * c[0] + m[4] * c[1] + m[5] * c[2],
          m[6] * c[0] + m[7] * c[1] + m[8] * c[2]};
}

Color xyz_to_ycxcz(const Color& c) {
  const float x = c[0] * kInvWhite[0], y = c[1] * kInvWhite[1], z = c[2] * kInvWhite[2];
  return {116.0f * y - 16.0f, 500.0f * (x - y), 200.0f * (y - z)};
}

Color ycxcz_to_xyz(const Color& c) {
  const float y = (c[0] + 16.0f) / 116.0f;
  return {(y + c[1] / 500.0f) * kWhite[0], y * kWhite[1], (y - c[2] / 200.0f) * kWhite[2]};
}

Color xyz_to_lab(const Color& c) { return lab_from_xyz(c[0], c[1], c[2], std_pow); }

Color hunt_adjust(const Color& lab) { return {lab[0], 0.01f * lab[0] * lab[1], 0.01f * lab[0] * lab[2]}; }

float hyab(const Color& p, const Color& q) {
  return std::fabs(p[0] - q[0]) + std::sqrt((p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
}

float max_color_difference() {
  static const float cmax = color_max_distance();
  return cmax;
}

float remap_color_difference(float distance) {
  const float cmax = max_color_difference(), knee = kPc * cmax;
  const float e = std::pow(distance, kQc);
  return e < knee ? e * (kPt / knee) : kPt + ((e - knee) / (cmax - knee)) * (1.0f - kPt);
}

float feature_difference(float edge_t, float point_t, float edge_r, float point_r) {
  const float d = std::max(std::fabs(edge_r - edge_t), std::fabs(point_r - point_t));
  return std::pow(d * float(1.0 / std::numbers::sqrt2), kQf);
}

float combine(float color_difference, float feature_diff) { return std::pow(color_difference, 1.0f - feature_diff); }

Color tone_map(FlipToneMapper t, const Color& c) {
  if (t == FlipToneMapper::Reinhard) {
    const float s = 1.0f / (1.0f + 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2]);
    return {c[0] * s, c[1] * s, c[2] * s};
  }
  const float* k = rational_coefficients(t);
  Color out;
  for (int i = 0; i < 3; ++i) out[std::size_t(i)] = (c[std::size_t(i)] * c[std::size_t(i)] * k[0] + c[std::size_t(i)] * k[1] + k[2]) /
                                                    (c[std::size_t(i)] * c[std::size_t(i)] * k[3] + c[std::size_t(i)] * k[4] + k[5]);
  return out;
}

int spatial_filter_radius(double ppd) {
  // The widest of the CSF Gaussians decides (b = 0.04 of Cz): 3 standard deviations, sqrt(b / (2 pi^2)) degrees.
  float max_b = 0.0f;
  for (const auto& c : kCsf) max_b = std::max({max_b, c.b1, c.b2});
  return int(std::ceil(3.0f * std::sqrt(max_b / (2.0f * float(kPi * kPi))) * float(ppd)));
}

int feature_filter_radius(double ppd) { return int(std::ceil(3.0f * (0.5f * kW * float(ppd)))); }

SpatialFilters spatial_filters(double ppd) {
  const int r = spatial_filter_radius(ppd);
  const float dx = 1.0f / float(ppd), pi = kPi, pi2 = float(kPi * kPi);
  auto gauss = [&](float x2, float a, float b) { return a * std::sqrt(pi / b) * std::exp(-pi2 * x2 / b); };
  // Cz's kernel is a sum of two Gaussians: each is split into two equal 1-D factors, sqrt(a sqrt(pi/b)) each.
  auto gauss_sqrt = [&](float x2, float a, float b) { return std::sqrt(a * std::sqrt(pi / b)) * std::exp(-pi2 * x2 / b); };
  SpatialFilters f;
  double sum[4] = {};
  for (int i = -r; i <= r; ++i) {
    const float x = float(i) * dx, x2 = x * x;
    f.y.push_back(gauss(x2, kCsf[0].a1, kCsf[0].b1));
    f.cx.push_back(gauss(x2, kCsf[1].a1, kCsf[1].b1));
    f.cz1.push_back(gauss_sqrt(x2, kCsf[2].a1, kCsf[2].b1));
    f.cz2.push_back(gauss_sqrt(x2, kCsf[2].a2, kCsf[2].b2));
    sum[0] += f.y.back();
    sum[1] += f.cx.back();
    sum[2] += f.cz1.back();
    sum[3] += f.cz2.back();
  }
  // The 2-D kernels must sum to 1: y (x) y and cx (x) cx each, and cz1 (x) cz1 + cz2 (x) cz2 together.
  const double cz_norm = 1.0 / std::sqrt(sum[2] * sum[2] + sum[3] * sum[3]);
  for (std::size_t i = 0; i < f.y.size(); ++i) {
    f.y[i] = float(f.y[i] / sum[0]);
    f.cx[i] = float(f.cx[i] / sum[1]);
    f.cz1[i] = float(f.cz1[i] * cz_norm);
    f.cz2[i] = float(f.cz2[i] * cz_norm);
  }
  return f;
}

FeatureFilters feature_filters(double ppd) {
  const float sigma = 0.5f * kW * float(ppd);
  const int r = int(std::ceil(3.0f * sigma));
  FeatureFilters f;
  double g_sum = 0, dg_pos = 0, dg_neg = 0, ddg_pos = 0, ddg_neg = 0;
  for (int i = -r; i <= r; ++i) {
    const float x = float(i);
    const float g = std::exp(-(x * x) / (2.0f * sigma * sigma));
    const float dg = -x * g;                                  // d/dx of the Gaussian (up to 1 / sigma^2)
    const float ddg = (x * x / (sigma * sigma) - 1.0f) * g;  // d^2/dx^2 (up to 1 / sigma^2)
    f.g.push_back(g);
    f.dg.push_back(dg);
    f.ddg.push_back(ddg);
    g_sum += g;
    (dg > 0 ? dg_pos : dg_neg) += std::fabs(dg);
    (ddg > 0 ? ddg_pos : ddg_neg) += std::fabs(ddg);
  }
  // Gaussian to sum 1; each derivative kernel to +1 over its positive and -1 over its negative weights.
  for (std::size_t i = 0; i < f.g.size(); ++i) {
    f.g[i] = float(f.g[i] / g_sum);
    f.dg[i] = float(f.dg[i] / (f.dg[i] > 0 ? dg_pos : dg_neg));
    f.ddg[i] = float(f.ddg[i] / (f.ddg[i] > 0 ? ddg_pos : ddg_neg));
  }
  return f;
}

FlipExposures automatic_exposures(const FlipImage& ref, std::size_t count, FlipToneMapper tone_mapper,
                                  const std::uint8_t* valid) {
  // x_max: the input the tone mapper maps to t = 0.85, the larger root of (k0 - t k3) x^2 + (k1 - t k4) x +
  // (k2 - t k5) = 0 (Reinhard's per-channel form has k = {0, 1, 0, 0, 1, 1}, as in the reference).
  static constexpr float kReinhard[6] = {0.0f, 1.0f, 0.0f, 0.0f, 1.0f, 1.0f};
  const float* k = tone_mapper == FlipToneMapper::Reinhard ? kReinhard : rational_coefficients(tone_mapper);
  const float t = 0.85f;
  const float a = k[0] - t * k[3], b = k[1] - t * k[4], c = k[2] - t * k[5];
  float x_max;
  if (a == 0.0f) {
    x_max = -c / b;
  } else {
    const float d1 = -0.5f * (b / a);
    x_max = d1 + std::sqrt(d1 * d1 - c / a);
  }
  std::vector<float> y(count);
  float y_max = -std::numeric_limits<float>::infinity();
  float y_min_positive = std::numeric_limits<float>::infinity();
  for (std::size_t i = 0; i < count; ++i) {
    const bool ok = !valid || valid[i];
    const float v = ok ? 0.2126f * ref.r[i] + 0.7152f * ref.g[i] + 0.0722f * ref.b[i] : 0.0f;
    y[i] = v;
    y_max = std::max(y_max, v);
    if (v > 0.0f) y_min_positive = std::min(y_min_positive, v);
  }
  FlipExposures e;
  if (count == 0 || !(y_max > 0.0f)) {
    e.count = 2;  // nothing lit: expose by 1 (the tone mapper sees the values as they are)
    return e;
  }
  const std::size_t mid = count / 2;
  std::nth_element(y.begin(), y.begin() + std::ptrdiff_t(mid), y.end());
  float y_median = y[mid];
  if (!(y_median > 0.0f)) y_median = y_min_positive;  // over half the pixels black (see flip.h)
  e.start = std::log2(x_max / y_max);
  e.stop = std::log2(x_max / y_median);
  e.count = int(std::max(2.0f, std::ceil(e.stop - e.start)));
  return e;
}

}  // namespace flip

// ---------------------------------------------------------------------------------------------------------
// Pixel loops

namespace {

using flip::Color;
constexpr int kStrip = 64;  // pixels per filter strip: 4 AVX-512 (8 AVX2) registers per accumulator

// How the input images become linear RGB in [0, 1] before YyCxCz.
enum class Prepare { Srgb, Linear, ToneRational, ToneReinhard };

// Plane storage with kStrip floats of zeroed slack, so strip loops may read (not use) past the last pixel.
struct Plane {
  std::vector<float> v;
  void resize(std::size_t n) { v.assign(n + kStrip, 0.0f); }
  float* data() { return v.data(); }
  const float* data() const { return v.data(); }
};

// Step (1): linear RGB in [0, 1] (decoded, or exposed by `scale` and tone-mapped, then clamped) -> YyCxCz.
// Invalid pixels are black in both images.
template <Prepare P>
void prepare_rows(const FlipImage& in, std::size_t n, const std::uint8_t* valid, float scale, const float* k,
                  float* Y, float* Cx, float* Cz) {
  parallel_chunks(n, [&](std::size_t b, std::size_t e) {
    const float* m = flip::kRgbToXyz;
    for (std::size_t i = b; i < e; ++i) {
      const bool ok = !valid || valid[i];
      float c[3] = {ok ? in.r[i] : 0.0f, ok ? in.g[i] : 0.0f, ok ? in.b[i] : 0.0f};
      if constexpr (P == Prepare::Srgb) {
        for (float& v : c) v = v <= 0.04045f ? v / 12.92f : fast_math::pow((v + 0.055f) / 1.055f, 2.4f);
      } else if constexpr (P == Prepare::ToneRational) {
        for (float& v : c) {
          v *= scale;
          v = (v * v * k[0] + v * k[1] + k[2]) / (v * v * k[3] + v * k[4] + k[5]);
        }
      } else if constexpr (P == Prepare::ToneReinhard) {
        for (float& v : c) v *= scale;
        const float s = 1.0f / (1.0f + 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2]);
        for (float& v : c) v *= s;
      }
      for (float& v : c) v = std::min(std::max(v, 0.0f), 1.0f);
      const float x = (m[0] * c[0] + m[1] * c[1] + m[2] * c[2]) * flip::kInvWhite[0];
      const float y = (m[3] * c[0] + m[4] * c[1] + m[5] * c[2]) * flip::kInvWhite[1];
      const float z = (m[6] * c[0] + m[7] * c[1] + m[8] * c[2]) * flip::kInvWhite[2];
      Y[i] = 116.0f * y - 16.0f;
      Cx[i] = 500.0f * (x - y);
      Cz[i] = 200.0f * (y - z);
    }
  });
}

// acc[k][i] += w_k[t] * src_t[i] over the taps, for K outputs of one strip; sources are per output and per tap.
template <int K>
inline void strip_fir(float (&acc)[K][kStrip], const float* const (&src)[K], std::ptrdiff_t step, int taps,
                      const float* const (&w)[K]) {
  for (int k = 0; k < K; ++k)
    for (int i = 0; i < kStrip; ++i) acc[k][i] = 0.0f;
  for (int t = 0; t < taps; ++t)
    for (int k = 0; k < K; ++k) {
      const float wt = w[k][t];
      const float* s = src[k] + std::ptrdiff_t(t) * step;
      for (int i = 0; i < kStrip; ++i) acc[k][i] += wt * s[i];
    }
}

struct Filters {
  double ppd = 0.0;
  int rs = 0, rf = 0;  // radii: spatial (CSF), feature
  flip::SpatialFilters spatial;
  flip::FeatureFilters feature;
};

// The seven horizontal outputs and the five per-image quantities.
enum { kHY, kHCx, kHCz1, kHCz2, kHG, kHDG, kHDDG, kHorizontal };
enum { kL, kA, kB, kEdge, kPoint, kProducts };

// Step (2): every 1-D horizontal filter of a row, borders clamped (each row is copied into a padded buffer).
void horizontal_pass(const float* Y, const float* Cx, const float* Cz, int w, int h, const Filters& f,
                     Plane (&out)[kHorizontal]) {
  parallel_rows(h, [&](int y0, int y1) {
    const int rs = f.rs, rf = f.rf;
    std::vector<float> pad_y(std::size_t(w + 2 * rs + kStrip)), pad_cx(pad_y.size()), pad_cz(pad_y.size());
    std::vector<float> pad_f(std::size_t(w + 2 * rf + kStrip));
    auto pad = [&](const float* row, int r, std::vector<float>& dst, bool feature) {
      for (int x = -r; x < w + r; ++x) {
        const float v = row[std::clamp(x, 0, w - 1)];
        dst[std::size_t(x + r)] = feature ? v * (1.0f / 116.0f) + 16.0f / 116.0f : v;  // Y to [0, 1]
      }
    };
    for (int y = y0; y < y1; ++y) {
      const std::size_t o = std::size_t(y) * std::size_t(w);
      pad(Y + o, rs, pad_y, false);
      pad(Cx + o, rs, pad_cx, false);
      pad(Cz + o, rs, pad_cz, false);
      pad(Y + o, rf, pad_f, true);
      const int ts = 2 * rs + 1, tf = 2 * rf + 1;
      for (int x0 = 0; x0 < w; x0 += kStrip) {
        const int m = std::min(kStrip, w - x0);
        float a[2][kStrip], c[2][kStrip], g[3][kStrip];
        const std::size_t xs = std::size_t(x0);
        strip_fir<2>(a, {pad_y.data() + xs, pad_cx.data() + xs}, 1, ts, {f.spatial.y.data(), f.spatial.cx.data()});
        strip_fir<2>(c, {pad_cz.data() + xs, pad_cz.data() + xs}, 1, ts, {f.spatial.cz1.data(), f.spatial.cz2.data()});
        strip_fir<3>(g, {pad_f.data() + xs, pad_f.data() + xs, pad_f.data() + xs}, 1, tf,
                     {f.feature.g.data(), f.feature.dg.data(), f.feature.ddg.data()});
        const float* res[kHorizontal] = {a[0], a[1], c[0], c[1], g[0], g[1], g[2]};
        for (int p = 0; p < kHorizontal; ++p) std::copy(res[p], res[p] + m, out[p].data() + o + xs);
      }
    }
  });
}

// Step (3): the vertical 1-D filters, and per pixel the Hunt-adjusted CIELab of the filtered colour and the
// edge and point magnitudes.
void vertical_pass(const Plane (&in)[kHorizontal], int w, int h, const Filters& f, Plane (&out)[kProducts]) {
  const auto fast_pow = [](float x, float p) { return fast_math::pow(x, p); };
  parallel_rows(h, [&](int y0, int y1) {
    const int rs = f.rs, rf = f.rf;
    for (int y = y0; y < y1; ++y) {
      for (int x0 = 0; x0 < w; x0 += kStrip) {
        const int m = std::min(kStrip, w - x0);
        const std::size_t xs = std::size_t(x0);
        // Tap rows are clamped at the borders, so each tap gets its own row pointer.
        float acc_s[4][kStrip] = {}, acc_f[4][kStrip] = {};
        for (int t = 0; t <= 2 * rs; ++t) {
          const std::size_t row = std::size_t(std::clamp(y + t - rs, 0, h - 1)) * std::size_t(w) + xs;
          const float* sy = in[kHY].data() + row;
          const float* sx = in[kHCx].data() + row;
          const float* s1 = in[kHCz1].data() + row;
          const float* s2 = in[kHCz2].data() + row;
          const std::size_t k = std::size_t(t);
          const float wy = f.spatial.y[k], wx = f.spatial.cx[k], w1 = f.spatial.cz1[k], w2 = f.spatial.cz2[k];
          for (int i = 0; i < kStrip; ++i) {
            acc_s[0][i] += wy * sy[i];
            acc_s[1][i] += wx * sx[i];
            acc_s[2][i] += w1 * s1[i];
            acc_s[3][i] += w2 * s2[i];
          }
        }
        for (int t = 0; t <= 2 * rf; ++t) {
          const std::size_t row = std::size_t(std::clamp(y + t - rf, 0, h - 1)) * std::size_t(w) + xs;
          const float* sdg = in[kHDG].data() + row;
          const float* sddg = in[kHDDG].data() + row;
          const float* sg = in[kHG].data() + row;
          const std::size_t k = std::size_t(t);
          const float g = f.feature.g[k], dg = f.feature.dg[k], ddg = f.feature.ddg[k];
          for (int i = 0; i < kStrip; ++i) {
            acc_f[0][i] += g * sdg[i];   // d/dx
            acc_f[1][i] += g * sddg[i];  // d2/dx2
            acc_f[2][i] += dg * sg[i];   // d/dy
            acc_f[3][i] += ddg * sg[i];  // d2/dy2
          }
        }
        const std::size_t o = std::size_t(y) * std::size_t(w) + xs;
        float* L = out[kL].data() + o;
        float* A = out[kA].data() + o;
        float* B = out[kB].data() + o;
        float* E = out[kEdge].data() + o;
        float* P = out[kPoint].data() + o;
        const float* mi = flip::kXyzToRgb;
        const float* mf = flip::kRgbToXyz;
        for (int i = 0; i < m; ++i) {
          // YyCxCz -> XYZ -> linear RGB clamped to [0, 1] (the reference's order) -> XYZ -> CIELab -> Hunt.
          const float yy = (acc_s[0][i] + 16.0f) / 116.0f;
          const float X = (yy + acc_s[1][i] / 500.0f) * flip::kWhite[0];
          const float Yv = yy * flip::kWhite[1];
          const float Z = (yy - (acc_s[2][i] + acc_s[3][i]) / 200.0f) * flip::kWhite[2];
          const float r = flip::clamp01(mi[0] * X + mi[1] * Yv + mi[2] * Z);
          const float g = flip::clamp01(mi[3] * X + mi[4] * Yv + mi[5] * Z);
          const float b = flip::clamp01(mi[6] * X + mi[7] * Yv + mi[8] * Z);
          const Color lab = flip::lab_from_xyz(mf[0] * r + mf[1] * g + mf[2] * b, mf[3] * r + mf[4] * g + mf[5] * b,
                                               mf[6] * r + mf[7] * g + mf[8] * b, fast_pow);
          L[i] = lab[0];
          A[i] = 0.01f * lab[0] * lab[1];
          B[i] = 0.01f * lab[0] * lab[2];
          E[i] = std::sqrt(acc_f[0][i] * acc_f[0][i] + acc_f[2][i] * acc_f[2][i]);
          P[i] = std::sqrt(acc_f[1][i] * acc_f[1][i] + acc_f[3][i] * acc_f[3][i]);
        }
      }
    }
  });
}

// Step (4): FLIP per pixel from the two images' quantities. Max: HDR-FLIP's running maximum over exposures
// (strictly greater replaces, as the reference), recording `exposure` in exposure_map when it is not null.
template <bool Max>
void combine_pass(const Plane (&ref)[kProducts], const Plane (&test)[kProducts], std::size_t n,
                  const std::uint8_t* valid, float* map, float* exposure_map, float exposure) {
  const float cmax = flip::max_color_difference(), knee = flip::kPc * cmax;
  const float below = flip::kPt / knee, above = (1.0f - flip::kPt) / (cmax - knee);
  const float inv_sqrt2 = float(1.0 / std::numbers::sqrt2);
  parallel_chunks(n, [&](std::size_t b, std::size_t e) {
    const float *L1 = ref[kL].data(), *A1 = ref[kA].data(), *B1 = ref[kB].data();
    const float *E1 = ref[kEdge].data(), *P1 = ref[kPoint].data();
    const float *L2 = test[kL].data(), *A2 = test[kA].data(), *B2 = test[kB].data();
    const float *E2 = test[kEdge].data(), *P2 = test[kPoint].data();
    for (std::size_t i = b; i < e; ++i) {
      const float da = A1[i] - A2[i], db = B1[i] - B2[i];
      const float distance = std::fabs(L1[i] - L2[i]) + std::sqrt(da * da + db * db);  // HyAB
      const float c = fast_math::pow(distance, flip::kQc);
      const float color = c < knee ? c * below : flip::kPt + (c - knee) * above;
      const float feature =
          std::sqrt(std::max(std::fabs(E1[i] - E2[i]), std::fabs(P1[i] - P2[i])) * inv_sqrt2);  // ^q_f = 0.5
      float v = fast_math::pow(color, 1.0f - feature);
      v = (!valid || valid[i]) ? v : 0.0f;
      if constexpr (Max) {
        const bool larger = v > map[i];
        map[i] = larger ? v : map[i];
        if (exposure_map) exposure_map[i] = larger ? exposure : exposure_map[i];
      } else {
        map[i] = v;
      }
    }
  });
}

Status check_inputs(const FlipImage& test, const FlipImage& ref, int width, int height, const float* map,
                    const FlipOptions& o) {
  if (!(o.pixels_per_degree > 0.0) || !std::isfinite(o.pixels_per_degree))
    return Error::usage("FLIP needs a positive, finite number of pixels per degree (got " +
                        std::to_string(o.pixels_per_degree) + "); the default is 67.0206");
  if (width <= 0 || height <= 0) return Error::input({}, "FLIP of an empty image: give images of at least 1x1 pixels");
  for (const FlipImage* im : {&test, &ref})
    if (!im->r || !im->g || !im->b) return Error::input({}, "FLIP needs three planes (R, G, B) per image; pass one plane three times for grey");
  if (!map) return Error::internal("FLIP: no output map given");
  return {};
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------
// The evaluator

struct FlipEvaluator::Workspace {
  std::size_t pixels = 0;
  Plane ycxcz[3];
  Plane horizontal[kHorizontal];
  Plane products[2][kProducts];  // [0]: reference, [1]: test
  Filters filters;

  void ensure(std::size_t n, double ppd) {
    if (n != pixels) {
      for (auto& p : ycxcz) p.resize(n);
      for (auto& p : horizontal) p.resize(n);
      for (auto& image : products)
        for (auto& p : image) p.resize(n);
      pixels = n;
    }
    if (filters.ppd != ppd) {
      filters.ppd = ppd;
      filters.rs = flip::spatial_filter_radius(ppd);
      filters.rf = flip::feature_filter_radius(ppd);
      filters.spatial = flip::spatial_filters(ppd);
      filters.feature = flip::feature_filters(ppd);
    }
  }

  // Steps (1)-(3) for one image into products[slot].
  void image(const FlipImage& in, int w, int h, const std::uint8_t* valid, Prepare how, float scale,
             FlipToneMapper tone, int slot) {
    const std::size_t n = std::size_t(w) * std::size_t(h);
    float* Y = ycxcz[0].data();
    float* Cx = ycxcz[1].data();
    float* Cz = ycxcz[2].data();
    const float* k = flip::rational_coefficients(tone);
    switch (how) {
      case Prepare::Srgb: prepare_rows<Prepare::Srgb>(in, n, valid, scale, k, Y, Cx, Cz); break;
      case Prepare::Linear: prepare_rows<Prepare::Linear>(in, n, valid, scale, k, Y, Cx, Cz); break;
      case Prepare::ToneRational: prepare_rows<Prepare::ToneRational>(in, n, valid, scale, k, Y, Cx, Cz); break;
      case Prepare::ToneReinhard: prepare_rows<Prepare::ToneReinhard>(in, n, valid, scale, k, Y, Cx, Cz); break;
    }
    horizontal_pass(Y, Cx, Cz, w, h, filters, horizontal);
    vertical_pass(horizontal, w, h, filters, products[slot]);
  }
};

FlipEvaluator::FlipEvaluator(FlipOptions options) : options_(options), work_(std::make_unique<Workspace>()) {}
FlipEvaluator::~FlipEvaluator() = default;
FlipEvaluator::FlipEvaluator(FlipEvaluator&&) noexcept = default;
FlipEvaluator& FlipEvaluator::operator=(FlipEvaluator&&) noexcept = default;

Status FlipEvaluator::ldr(const FlipImage& test, const FlipImage& reference, int width, int height,
                          const std::uint8_t* valid, float* map) {
  if (auto st = check_inputs(test, reference, width, height, map, options_); !st) return st;
  const std::size_t n = std::size_t(width) * std::size_t(height);
  work_->ensure(n, options_.pixels_per_degree);
  const Prepare how = options_.ldr_input == FlipLdrInput::Srgb ? Prepare::Srgb : Prepare::Linear;
  work_->image(reference, width, height, valid, how, 1.0f, options_.tone_mapper, 0);
  work_->image(test, width, height, valid, how, 1.0f, options_.tone_mapper, 1);
  combine_pass<false>(work_->products[0], work_->products[1], n, valid, map, nullptr, 0.0f);
  return {};
}

Expected<FlipExposures> FlipEvaluator::hdr(const FlipImage& test, const FlipImage& reference, int width, int height,
                                           const std::uint8_t* valid, float* map, float* exposure_map) {
  if (auto st = check_inputs(test, reference, width, height, map, options_); !st) return st.error();
  const std::size_t n = std::size_t(width) * std::size_t(height);
  FlipExposures e;
  if (!options_.start_exposure || !options_.stop_exposure)
    e = flip::automatic_exposures(reference, n, options_.tone_mapper, valid);
  if (options_.start_exposure) e.start = *options_.start_exposure;
  if (options_.stop_exposure) e.stop = *options_.stop_exposure;
  if (!(e.start <= e.stop))
    return Error::usage("HDR-FLIP: the start exposure (" + std::to_string(e.start) + ") must not exceed the stop exposure (" +
                        std::to_string(e.stop) + ")");
  if (options_.exposures == 1 || options_.exposures < 0)
    return Error::usage("HDR-FLIP needs at least 2 exposures (got " + std::to_string(options_.exposures) +
                        "); 0 chooses max(2, ceil(stop - start))");
  e.count = options_.exposures > 0 ? options_.exposures : int(std::max(2.0f, std::ceil(e.stop - e.start)));
  work_->ensure(n, options_.pixels_per_degree);
  std::fill(map, map + n, 0.0f);
  if (exposure_map) std::fill(exposure_map, exposure_map + n, 0.0f);
  const Prepare how = options_.tone_mapper == FlipToneMapper::Reinhard ? Prepare::ToneReinhard : Prepare::ToneRational;
  const float step = (e.stop - e.start) / float(e.count - 1);
  for (int i = 0; i < e.count; ++i) {
    const float scale = std::pow(2.0f, e.start + float(i) * step);
    work_->image(reference, width, height, valid, how, scale, options_.tone_mapper, 0);
    work_->image(test, width, height, valid, how, scale, options_.tone_mapper, 1);
    combine_pass<true>(work_->products[0], work_->products[1], n, valid, map, exposure_map,
                       float(i) / float(e.count - 1));
  }
  return e;
}

// ---------------------------------------------------------------------------------------------------------
// Pooling

FlipStats flip_statistics(std::span<const float> map, const std::uint8_t* valid) {
  // Fixed chunks, each with its own histogram of value sums, merged in chunk order: the result does not depend
  // on the thread count. A value's bucket grows with the value, so a percentile's bucket is found from the
  // cumulative bucket sums and only that bucket's values need sorting.
  constexpr int kBuckets = 4096;
  constexpr std::size_t kChunks = 32;
  const std::size_t n = map.size();
  struct Chunk {
    std::vector<double> sum = std::vector<double>(kBuckets, 0.0);
    std::size_t count = 0;
    float min = std::numeric_limits<float>::infinity(), max = -std::numeric_limits<float>::infinity();
  };
  std::vector<Chunk> chunks(kChunks);
  auto bucket_of = [](float v) { return std::clamp(int(v * float(kBuckets)), 0, kBuckets - 1); };
  parallel_chunks(
      kChunks,
      [&](std::size_t c0, std::size_t c1) {
        for (std::size_t c = c0; c < c1; ++c) {
          Chunk& ch = chunks[c];
          for (std::size_t i = n * c / kChunks; i < n * (c + 1) / kChunks; ++i) {
            if (valid && !valid[i]) continue;
            const float v = map[i];
            ch.sum[std::size_t(bucket_of(v))] += v;
            ++ch.count;
            ch.min = std::min(ch.min, v);
            ch.max = std::max(ch.max, v);
          }
        }
      },
      1);
  FlipStats s;
  std::vector<double> bucket(kBuckets, 0.0);
  float mn = std::numeric_limits<float>::infinity(), mx = -mn;
  for (const Chunk& ch : chunks) {
    for (int b = 0; b < kBuckets; ++b) bucket[std::size_t(b)] += ch.sum[std::size_t(b)];
    s.pixels += ch.count;
    mn = std::min(mn, ch.min);
    mx = std::max(mx, ch.max);
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (s.pixels == 0) return {nan, nan, nan, nan, nan, nan, 0};
  double total = 0.0;
  for (double v : bucket) total += v;
  s.mean = total / double(s.pixels);
  s.min = mn;
  s.max = mx;
  auto percentile = [&](double p) {
    const double target = p * total;
    double before = 0.0;
    int b = 0;
    while (b < kBuckets && !(before + bucket[std::size_t(b)] > target)) before += bucket[std::size_t(b++)];
    if (b == kBuckets) return 0.0;  // every value 0: nothing exceeds 0 (the reference returns 0 too)
    std::vector<float> values;
    for (std::size_t i = 0; i < n; ++i)
      if ((!valid || valid[i]) && bucket_of(map[i]) == b) values.push_back(map[i]);
    std::sort(values.begin(), values.end());
    double running = before;
    for (float v : values) {
      running += v;
      if (running > target) return double(v);
    }
    return values.empty() ? 0.0 : double(values.back());  // rounding of the bucket sums: the bucket's largest
  };
  s.weighted_quartile_1 = percentile(0.25);
  s.weighted_median = percentile(0.5);
  s.weighted_quartile_3 = percentile(0.75);
  return s;
}

Expected<FlipStats> evaluate_flip(FlipRange range, const FlipImage& test, const FlipImage& reference, int width,
                                  int height, const FlipOptions& options, float* map, FlipExposures* exposures) {
  std::vector<float> own;
  if (!map && width > 0 && height > 0) {
    own.resize(std::size_t(width) * std::size_t(height));
    map = own.data();
  }
  FlipEvaluator evaluator(options);
  if (range == FlipRange::Ldr) {
    if (auto st = evaluator.ldr(test, reference, width, height, nullptr, map); !st) return st.error();
  } else {
    auto e = evaluator.hdr(test, reference, width, height, nullptr, map);
    if (!e) return e.error();
    if (exposures) *exposures = *e;
  }
  return flip_statistics({map, std::size_t(width) * std::size_t(height)});
}

}  // namespace temporal
