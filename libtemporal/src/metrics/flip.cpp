// FLIP and HDR-FLIP (temporal/metrics/flip.h). The header gives the definitions and the paper steps; this file
// explains the implementation choices.
//
// Layout of the work, per image: (1+2) one horizontal pass: each row goes to YyCxCz (exposure and tone mapping
// for HDR-FLIP, sRGB decoding for LDR inputs) in a row buffer and all seven 1-D filters a row needs run on it
// (CSF of Y, Cx, the two Gaussians of Cz, and the feature Gaussian with its two derivatives); (3) two vertical
// passes over tiles finish the 2-D filters and turn them, strip by strip, into the five per-pixel quantities the
// comparison needs (Hunt-adjusted CIELab, edge and point magnitudes). The test and the reference go through
// them separately, so a reference could be kept for several tests; (4) a point-wise pass combines the two into
// the FLIP map. Every pass is parallel (rows, tiles or chunks); the filters work on strips of kStrip pixels whose
// accumulators stay in vector registers.
#include "temporal/metrics/flip.h"

#include "temporal/core/fast_math.h"
#include "temporal/core/isa.h"
#include "temporal/core/parallel.h"

#include <algorithm>
#include <cmath>
#include <cstring>
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

// CIELab from XYZ with a given cube root: the scalar API uses std::pow(t, 1/3) as the reference, the pixel
// loops fast_math::cbrt.
template <typename Cbrt>
inline Color lab_from_xyz(float x, float y, float z, Cbrt cbrt) {
  auto f = [&](float t) {  // both branches evaluated, then selected: the pixel loops stay branch-free
    const float root = cbrt(t), linear = kLabFactor * t + kLabTerm;
    return t > kLabDeltaCube ? root : linear;
  };
  const float fx = f(x * kInvWhite[0]), fy = f(y * kInvWhite[1]), fz = f(z * kInvWhite[2]);
  return {116.0f * fy - 16.0f, 500.0f * (fx - fy), 200.0f * (fy - fz)};
}

inline float std_cbrt(float t) { return std::pow(t, 1.0f / 3.0f); }

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

Color xyz_to_lab(const Color& c) { return lab_from_xyz(c[0], c[1], c[2], std_cbrt); }

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
constexpr int kStrip = 64;  // pixels per filter strip: 4 AVX-512, 8 AVX2 or 16 SSE registers per accumulator

// How the input images become linear RGB in [0, 1] before YyCxCz.
enum class Prepare { Srgb, Linear, ToneRational, ToneReinhard };

// Plane storage: `margin` replicated rows above and below the image (so vertical filters need no clamping),
// and kStrip floats of zeroed slack at the end, so strip loops may read (not use) past the last pixel.
struct Plane {
  std::vector<float> v;
  std::size_t width = 0;
  int margin = 0;
  void resize(std::size_t w, int h, int m = 0) {
    width = w;
    margin = m;
    v.assign(w * std::size_t(h + 2 * m) + kStrip, 0.0f);
  }
  float* data() { return v.data() + std::size_t(margin) * width; }  // row 0
  const float* data() const { return v.data() + std::size_t(margin) * width; }
  // Copies row 0 into the margin rows above and row h - 1 into those below.
  void fill_margins(int h) {
    for (int r = 1; r <= margin; ++r) {
      std::memcpy(data() - std::size_t(r) * width, data(), width * sizeof(float));
      std::memcpy(data() + std::size_t(h - 1 + r) * width, data() + std::size_t(h - 1) * width, width * sizeof(float));
    }
  }
};

struct Filters {
  double ppd = 0.0;
  int rs = 0, rf = 0;  // radii: spatial (CSF), feature
  int ry = 0, rcx = 0;  // radii of the Y and Cx kernels once their negligible outer taps are dropped
  flip::SpatialFilters spatial;
  flip::FeatureFilters feature;

  void set(double pixels_per_degree) {
    ppd = pixels_per_degree;
    rs = flip::spatial_filter_radius(ppd);
    rf = flip::feature_filter_radius(ppd);
    spatial = flip::spatial_filters(ppd);
    feature = flip::feature_filters(ppd);
    ry = trim(spatial.y);
    rcx = trim(spatial.cx);
  }

  // The narrow Y and Cx Gaussians (sigma about 1 pixel at 67 ppd) span the radius of the widest CSF Gaussian
  // (Cz's, 10 pixels), as in the reference. Their outer taps below 2^-24 of the centre tap move a filtered value
  // by less than its own float rounding, so they are dropped (after the normalisation over all taps): 11 and 13
  // taps instead of 21 at 67 ppd.
  static int trim(std::vector<float>& taps) {
    int r = int(taps.size() / 2);
    const float limit = taps[std::size_t(r)] * 0x1p-24f;
    while (r > 0 && taps.front() < limit && taps.back() < limit) {
      taps.erase(taps.begin());
      taps.pop_back();
      --r;
    }
    return r;
  }
};

// The seven horizontal outputs and the five per-image quantities.
enum { kHY, kHCx, kHCz1, kHCz2, kHG, kHDG, kHDDG, kHorizontal };
enum { kL, kA, kB, kEdge, kPoint, kProducts };

// Steps (1) and (2): each row goes to YyCxCz (and Yf, Y normalised to [0, 1] for the feature filters) in row
// buffers extended by `margin` pixels on both sides with the edge values (the reference's clamped borders), and
// every 1-D horizontal filter runs on those buffers. The outputs' margin rows are filled afterwards, for the
// vertical filters. Preparing rows here rather than in a pass of its own saves writing and reading four planes.
struct RowInput {
  const FlipImage* image;
  const std::uint8_t* valid;
  Prepare how;
  float scale;
  const float* k;
};

// fast_math::cbrt for flip::lab_from_xyz in the kernels. Defined here, for the baseline, so that the baseline
// template inlines it in every copy (a lambda defined in a copy has the copy's target and would be called).
struct FastCbrt {
  float operator()(float t) const { return fast_math::cbrt(t); }
};

// flip_statistics' buckets: kPoolBuckets over [0, 1], a value's bucket growing with the value (the pooling
// kernels and flip_statistics share it; defined for the baseline, inlined into every copy).
constexpr int kPoolBuckets = 1024;
constexpr std::size_t kPoolLanes = 4;  // FLIP values crowd into few buckets: four interleaved histograms keep the
                                       // additions to one bucket from waiting on each other
inline int pool_bucket(float v) { return std::clamp(int(v * float(kPoolBuckets)), 0, kPoolBuckets - 1); }

// ---------------------------------------------------------------------------------------------------------
// The kernel copies, one per instruction set (temporal/core/isa.h): the same source, flip_kernels.inc, with the
// vector width and register count of the target. The copies differ only in FMA contraction (v2 has none).
#if TEMPORAL_ISA_DISPATCH
namespace v2 {
constexpr int kLanes = 4, kRegisters = 16;  // SSE
#include "flip_kernels.inc"
}  // namespace v2
TEMPORAL_ISA_V3_BEGIN
namespace v3 {
constexpr int kLanes = 8, kRegisters = 16;  // AVX2
#include "flip_kernels.inc"
}  // namespace v3
TEMPORAL_ISA_END
TEMPORAL_ISA_V4_BEGIN
namespace v4 {
constexpr int kLanes = 16, kRegisters = 32;  // AVX-512
#include "flip_kernels.inc"
}  // namespace v4
TEMPORAL_ISA_END
#else
namespace native {
#if defined(__AVX512F__)
constexpr int kLanes = 16, kRegisters = 32;
#elif defined(__AVX__)
constexpr int kLanes = 8, kRegisters = 16;
#elif defined(__aarch64__)
constexpr int kLanes = 4, kRegisters = 32;  // NEON
#else
constexpr int kLanes = 4, kRegisters = 16;
#endif
#include "flip_kernels.inc"
}  // namespace native
#endif

struct Kernels {
  void (*image)(const RowInput&, int, int, const Filters&, Plane (&)[kHorizontal], Plane (&)[kProducts]);
  void (*combine)(bool, const Plane (&)[kProducts], const Plane (&)[kProducts], std::size_t, const std::uint8_t*,
                  float*, float*, float);
  void (*pool_histogram)(const float*, const std::uint8_t*, std::size_t, std::size_t, double*, std::size_t&, float&,
                         float&);
  bool (*pool_block_hits)(const float*, std::size_t, std::size_t, const int (&)[3]);
};

const Kernels& kernels() {
#if TEMPORAL_ISA_DISPATCH
  static constexpr Kernels table[3] = {{v2::image, v2::combine, v2::pool_histogram, v2::pool_block_hits},
                                       {v3::image, v3::combine, v3::pool_histogram, v3::pool_block_hits},
                                       {v4::image, v4::combine, v4::pool_histogram, v4::pool_block_hits}};
  return table[int(isa::active())];  // Level::V2, V3, V4 are 0, 1, 2
#else
  static constexpr Kernels table{native::image, native::combine, native::pool_histogram, native::pool_block_hits};
  return table;
#endif
}

Status check_inputs(const FlipImage& test, const FlipImage& ref, int width, int height, const float* map,
                    const FlipOptions& o) {
  if (!(o.pixels_per_degree >= kFlipMinPixelsPerDegree && o.pixels_per_degree <= kFlipMaxPixelsPerDegree))
    return Error::usage("FLIP needs pixels per degree in [1, 1000] (got " + std::to_string(o.pixels_per_degree) +
                        "); the default is 67.0206");
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
  int width = 0, height = 0;
  Plane horizontal[kHorizontal];
  Plane products[2][kProducts];  // [0]: reference, [1]: test
  Plane exposure_scratch;
  Filters filters;

  void ensure(int w, int h, double ppd) {
    if (filters.ppd != ppd) filters.set(ppd);
    const int margin = std::max(filters.rs, filters.rf);
    if (w != width || h != height || margin != horizontal[0].margin) {
      for (auto& p : horizontal) p.resize(std::size_t(w), h, margin);
      for (auto& image : products)
        for (auto& p : image) p.resize(std::size_t(w), h);
      exposure_scratch.resize(std::size_t(w), h);
      width = w;
      height = h;
    }
  }

  // Steps (1)-(3) for one image into products[slot].
  void image(const FlipImage& in, int w, int h, const std::uint8_t* valid, Prepare how, float scale,
             FlipToneMapper tone, int slot) {
    const RowInput rows{&in, valid, how, scale, flip::rational_coefficients(tone)};
    kernels().image(rows, w, h, filters, horizontal, products[slot]);
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
  work_->ensure(width, height, options_.pixels_per_degree);
  const Prepare how = options_.ldr_input == FlipLdrInput::Srgb ? Prepare::Srgb : Prepare::Linear;
  work_->image(reference, width, height, valid, how, 1.0f, options_.tone_mapper, 0);
  work_->image(test, width, height, valid, how, 1.0f, options_.tone_mapper, 1);
  kernels().combine(false, work_->products[0], work_->products[1], n, valid, map, nullptr, 0.0f);
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
  work_->ensure(width, height, options_.pixels_per_degree);
  std::fill(map, map + n, 0.0f);
  // Without a caller's exposure map the running one goes to scratch (a store under a null test would keep the
  // combine loop from vectorising).
  float* exposures = exposure_map ? exposure_map : work_->exposure_scratch.data();
  std::fill(exposures, exposures + n, 0.0f);
  const Prepare how = options_.tone_mapper == FlipToneMapper::Reinhard ? Prepare::ToneReinhard : Prepare::ToneRational;
  const float step = (e.stop - e.start) / float(e.count - 1);
  for (int i = 0; i < e.count; ++i) {
    const float scale = std::pow(2.0f, e.start + float(i) * step);
    work_->image(reference, width, height, valid, how, scale, options_.tone_mapper, 0);
    work_->image(test, width, height, valid, how, scale, options_.tone_mapper, 1);
    const float which = float(i) / float(e.count - 1);
    kernels().combine(true, work_->products[0], work_->products[1], n, valid, map, exposures, which);
  }
  return e;
}

// ---------------------------------------------------------------------------------------------------------
// Pooling

FlipStats flip_statistics(std::span<const float> map, const std::uint8_t* valid) {
  // Two parallel passes over fixed chunks (merged in chunk order, so the result does not depend on the thread
  // count). A value's bucket grows with the value, so the bucket holding each weighted percentile follows from
  // the cumulative bucket sums of pass 1, and pass 2 collects only those buckets' values, which are sorted.
  constexpr int kBuckets = kPoolBuckets;
  constexpr std::size_t kChunks = 32;
  const std::size_t n = map.size();
  auto valid_at = [&](std::size_t i) { return !valid || valid[i] != 0; };
  const Kernels& kern = kernels();
  struct Chunk {
    std::vector<double> sum;
    std::size_t count = 0;
    float min = std::numeric_limits<float>::infinity(), max = -std::numeric_limits<float>::infinity();
    std::vector<float> picked[3];
  };
  std::vector<Chunk> chunks(kChunks);
  parallel_chunks(
      kChunks,
      [&](std::size_t c0, std::size_t c1) {
        for (std::size_t c = c0; c < c1; ++c) {
          Chunk& ch = chunks[c];
          std::vector<double> lanes(kPoolLanes * kBuckets, 0.0);
          kern.pool_histogram(map.data(), valid, n * c / kChunks, n * (c + 1) / kChunks, lanes.data(), ch.count,
                              ch.min, ch.max);
          ch.sum.assign(kBuckets, 0.0);
          for (std::size_t l = 0; l < kPoolLanes; ++l)
            for (std::size_t b = 0; b < kBuckets; ++b) ch.sum[b] += lanes[l * kBuckets + b];
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
  // The bucket where the running sum first exceeds p * total, and the sum of the buckets below it.
  const double fractions[3] = {0.25, 0.5, 0.75};
  int target[3];
  double before[3];
  for (int q = 0; q < 3; ++q) {
    double sum = 0.0;
    int b = 0;
    while (b < kBuckets && !(sum + bucket[std::size_t(b)] > fractions[q] * total)) sum += bucket[std::size_t(b++)];
    target[q] = b;  // kBuckets: every value is 0, nothing exceeds 0 (the reference answers 0 too)
    before[q] = sum;
  }
  parallel_chunks(
      kChunks,
      [&](std::size_t c0, std::size_t c1) {
        for (std::size_t c = c0; c < c1; ++c) {
          const std::size_t i0 = n * c / kChunks, i1 = n * (c + 1) / kChunks;
          // Blocks of 64 values: a vectorised test whether any is in a target bucket (rarely), then a scalar
          // look at the blocks that have one.
          for (std::size_t b0 = i0; b0 < i1; b0 += 64) {
            const std::size_t b1 = std::min(i1, b0 + 64);
            if (!kern.pool_block_hits(map.data(), b0, b1, target)) continue;
            for (std::size_t i = b0; i < b1; ++i) {
              if (!valid_at(i)) continue;
              const int b = pool_bucket(map[i]);
              for (int q = 0; q < 3; ++q)
                if (b == target[q]) chunks[c].picked[q].push_back(map[i]);
            }
          }
        }
      },
      1);
  double result[3];
  for (int q = 0; q < 3; ++q) {
    std::vector<float> values;
    for (const Chunk& ch : chunks) values.insert(values.end(), ch.picked[q].begin(), ch.picked[q].end());
    std::sort(values.begin(), values.end());
    result[q] = target[q] == kBuckets || values.empty() ? 0.0 : double(values.back());  // fallback: see below
    double running = before[q];
    for (float v : values)
      if ((running += v) > fractions[q] * total) {
        result[q] = v;
        break;
      }
    // Without a break, the bucket sums' rounding differs from this running sum: the bucket's largest value.
  }
  s.weighted_quartile_1 = result[0];
  s.weighted_median = result[1];
  s.weighted_quartile_3 = result[2];
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
