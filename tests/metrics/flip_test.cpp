// FLIP's pieces against values computed by hand (the derivations are in the comments), and properties of the
// whole map: identical images give 0, a uniform colour difference gives the colour pipeline's value, invalid
// pixels stay out, LDR input encodings agree. Agreement with NVIDIA's tool: flip_reference_test.cpp.
#include "temporal/metrics/flip.h"

#include <gtest/gtest.h>

#include <limits>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

namespace temporal {
namespace {

using flip::Color;

// CIELab L of a neutral grey of linear value y (white Y = 1): 116 y^(1/3) - 16 above (6/29)^3.
double lab_l(double y) { return 116.0 * std::cbrt(y) - 16.0; }

TEST(FlipPieces, SrgbDecoding) {
  EXPECT_NEAR(flip::srgb_to_linear(0.04f), 0.04 / 12.92, 1e-9);                       // linear segment
  EXPECT_NEAR(flip::srgb_to_linear(0.5f), std::pow(0.555 / 1.055, 2.4), 1e-7);        // 0.214041
  EXPECT_NEAR(flip::srgb_to_linear(1.0f), 1.0, 1e-7);
}

TEST(FlipPieces, ColourSpacesOfWhiteBlackAndGrey) {
  // The rows of the RGB -> XYZ matrix sum to the D65 white: 23359437 / 24577794, 1, 80288307 / 73733382.
  const Color white = flip::linear_rgb_to_xyz({1.0f, 1.0f, 1.0f});
  EXPECT_NEAR(white[0], 23359437.0 / 24577794.0, 1e-6);
  EXPECT_NEAR(white[1], 1.0, 1e-6);
  EXPECT_NEAR(white[2], 80288307.0 / 73733382.0, 1e-6);
  // White is (100, 0, 0) in YyCxCz and in CIELab; black is (-16, 0, 0) in YyCxCz (no cube root) and L = 0.
  const Color w_ycxcz = flip::xyz_to_ycxcz(white), w_lab = flip::xyz_to_lab(white);
  for (const Color& c : {w_ycxcz, w_lab}) {
    EXPECT_NEAR(c[0], 100.0, 1e-4);
    EXPECT_NEAR(c[1], 0.0, 1e-3);
    EXPECT_NEAR(c[2], 0.0, 1e-3);
  }
  const Color black = flip::xyz_to_ycxcz({0.0f, 0.0f, 0.0f});
  EXPECT_NEAR(black[0], -16.0, 1e-6);
  EXPECT_NEAR(flip::xyz_to_lab({0.0f, 0.0f, 0.0f})[0], 0.0, 1e-5);  // 116 * 4/29 - 16 = 0 (linear segment)
  // Grey 0.18: L = 116 * 0.18^(1/3) - 16 = 49.4962, a = b = 0.
  const Color grey = flip::xyz_to_lab(flip::linear_rgb_to_xyz({0.18f, 0.18f, 0.18f}));
  EXPECT_NEAR(grey[0], lab_l(0.18), 1e-3);
  EXPECT_NEAR(grey[1], 0.0, 1e-3);
  EXPECT_NEAR(grey[2], 0.0, 1e-3);
  // YyCxCz is linear and invertible: round trip of an arbitrary colour.
  const Color c = {0.3f, 0.6f, 0.1f};
  const Color back = flip::xyz_to_linear_rgb(flip::ycxcz_to_xyz(flip::xyz_to_ycxcz(flip::linear_rgb_to_xyz(c))));
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(back[std::size_t(i)], c[std::size_t(i)], 1e-5);
}

TEST(FlipPieces, HuntAndHyab) {
  const Color h = flip::hunt_adjust({50.0f, 20.0f, -10.0f});  // (L, 0.01 L a, 0.01 L b)
  EXPECT_FLOAT_EQ(h[0], 50.0f);
  EXPECT_FLOAT_EQ(h[1], 10.0f);
  EXPECT_FLOAT_EQ(h[2], -5.0f);
  // |50 - 40| + sqrt(3^2 + 4^2) = 15: city block on L, Euclidean on (a, b).
  EXPECT_FLOAT_EQ(flip::hyab({50.0f, 10.0f, -5.0f}, {40.0f, 13.0f, -1.0f}), 15.0f);
}

// c_max by hand, in double: Hunt-adjusted CIELab of linear green and blue, their HyAB, to the power 0.7.
double hand_cmax() {
  const double m[3][3] = {{10135552.0 / 24577794, 8788810.0 / 24577794, 4435075.0 / 24577794},
                          {2613072.0 / 12288897, 8788810.0 / 12288897, 887015.0 / 12288897},
                          {1425312.0 / 73733382, 8788810.0 / 73733382, 70074185.0 / 73733382}};
  const double white[3] = {0.950428545, 1.0, 1.088900371};
  auto lab_hunt = [&](int column) {
    double f[3];
    for (int i = 0; i < 3; ++i) f[i] = std::cbrt(m[i][column] / white[i]);  // all above (6/29)^3
    const double l = 116 * f[1] - 16, a = 500 * (f[0] - f[1]), b = 200 * (f[1] - f[2]);
    return std::array<double, 3>{l, 0.01 * l * a, 0.01 * l * b};
  };
  const auto g = lab_hunt(1), b = lab_hunt(2);
  return std::pow(std::fabs(g[0] - b[0]) + std::hypot(g[1] - b[1], g[2] - b[2]), 0.7);
}

TEST(FlipPieces, MaxColourDifferenceAndRemapping) {
  const double cmax = hand_cmax();  // 41.2 (HyAB of green and blue: 203)
  EXPECT_NEAR(flip::max_color_difference(), cmax, 1e-3 * cmax);
  EXPECT_GT(cmax, 40.0);
  EXPECT_LT(cmax, 43.0);
  // Re-mapping: 0 -> 0; the knee (HyAB^0.7 = 0.4 cmax) -> 0.95; half the knee -> 0.475; c_max -> 1.
  auto hyab_for = [](double e) { return float(std::pow(e, 1.0 / 0.7)); };
  EXPECT_EQ(flip::remap_color_difference(0.0f), 0.0f);
  EXPECT_NEAR(flip::remap_color_difference(hyab_for(0.4 * cmax)), 0.95, 1e-4);
  EXPECT_NEAR(flip::remap_color_difference(hyab_for(0.2 * cmax)), 0.475, 1e-4);
  EXPECT_NEAR(flip::remap_color_difference(hyab_for(cmax)), 1.0, 1e-4);
  // Above the knee the remaining 0.05 is spread linearly: 0.7 cmax -> 0.95 + 0.05 * 0.3 / 0.6 = 0.975.
  EXPECT_NEAR(flip::remap_color_difference(hyab_for(0.7 * cmax)), 0.975, 1e-4);
}

TEST(FlipPieces, FeatureDifferenceAndCombination) {
  // (max(|0.5 - 0|, |0 - 0|) / sqrt 2)^0.5 = 0.353553^0.5 = 0.594604; the larger of edge and point decides.
  EXPECT_NEAR(flip::feature_difference(0.5f, 0.0f, 0.0f, 0.0f), 0.594604, 1e-6);
  EXPECT_NEAR(flip::feature_difference(0.1f, 0.2f, 0.3f, 0.7f), std::sqrt(0.5 / std::sqrt(2.0)), 1e-6);
  EXPECT_EQ(flip::feature_difference(0.3f, 0.2f, 0.3f, 0.2f), 0.0f);
  EXPECT_NEAR(flip::combine(0.25f, 0.5f), 0.5, 1e-7);  // 0.25^(1 - 0.5)
  EXPECT_NEAR(flip::combine(0.3f, 0.0f), 0.3, 1e-7);   // no feature difference: the colour error
  EXPECT_EQ(flip::combine(0.0f, 0.3f), 0.0f);
}

TEST(FlipPieces, ToneMappers) {
  // ACES (0.6 pre-exposure cancelled) at 1: (0.36 * 2.51 + 0.018) / (0.36 * 2.43 + 0.354 + 0.14) = 0.673291.
  const Color aces = flip::tone_map(FlipToneMapper::Aces, {1.0f, 0.0f, 4.0f});
  EXPECT_NEAR(aces[0], (0.36 * 2.51 + 0.018) / (0.36 * 2.43 + 0.354 + 0.14), 1e-6);
  EXPECT_EQ(aces[1], 0.0f);
  EXPECT_NEAR(aces[2], (16 * 0.36 * 2.51 + 4 * 0.018) / (16 * 0.36 * 2.43 + 4 * 0.354 + 0.14), 1e-6);
  // Reinhard divides by 1 + luminance: grey 1 -> 0.5.
  const Color r = flip::tone_map(FlipToneMapper::Reinhard, {1.0f, 1.0f, 1.0f});
  for (float v : r) EXPECT_NEAR(v, 0.5, 1e-6);
  // Hable's rational fit at 1: (0.231683 + 0.013791) / (0.18 + 0.3 + 0.018).
  EXPECT_NEAR(flip::tone_map(FlipToneMapper::Hable, {1.0f, 1.0f, 1.0f})[0], 0.245474 / 0.498, 1e-6);
}

TEST(FlipPieces, AutomaticExposures) {
  // Grey pixels of luminance 0.5, 1, 2, 8: Y_max = 8, Y_median = the upper middle value = 2 (as the reference's
  // nth_element at n / 2). x_max solves ACES(x) = 0.85: (k0 - 0.85 k3) x^2 + (k1 - 0.85 k4) x - 0.85 k5 = 0.
  const std::vector<float> v = {2.0f, 0.5f, 8.0f, 1.0f};
  const FlipImage img{v.data(), v.data(), v.data()};
  const double a = 0.36 * 2.51 - 0.85 * 0.36 * 2.43, b = 0.018 - 0.85 * 0.354, c = -0.85 * 0.14;
  const double x_max = (-b + std::sqrt(b * b - 4 * a * c)) / (2 * a);  // 2.1189
  const FlipExposures e = flip::automatic_exposures(img, v.size(), FlipToneMapper::Aces);
  EXPECT_NEAR(e.start, std::log2(x_max / 8.0), 1e-5);
  EXPECT_NEAR(e.stop, std::log2(x_max / 2.0), 1e-5);
  EXPECT_EQ(e.count, 2);  // max(2, ceil(stop - start)) = max(2, ceil(2))
  // More than half black: the smallest positive luminance stands in for the median (0.5 here).
  const std::vector<float> dark = {0.0f, 0.0f, 0.0f, 0.5f, 8.0f};
  const FlipExposures d = flip::automatic_exposures({dark.data(), dark.data(), dark.data()}, dark.size(),
                                                    FlipToneMapper::Aces);
  EXPECT_NEAR(d.stop, std::log2(x_max / 0.5), 1e-5);
  EXPECT_EQ(d.count, 4);  // ceil(log2(16)) = 4
}

TEST(FlipPieces, FilterSizesAndNormalisation) {
  // CSF radius: ceil(3 sqrt(0.04 / (2 pi^2)) ppd) = ceil(0.135047 ppd): 10 at 67.02, 6 at 40.
  EXPECT_EQ(flip::spatial_filter_radius(kFlipDefaultPixelsPerDegree), 10);
  EXPECT_EQ(flip::spatial_filter_radius(40.0), 6);
  // Feature radius: ceil(3 * 0.5 * 0.082 ppd) = ceil(0.123 ppd): 9 at 67.02, 5 at 40.
  EXPECT_EQ(flip::feature_filter_radius(kFlipDefaultPixelsPerDegree), 9);
  EXPECT_EQ(flip::feature_filter_radius(40.0), 5);
  const auto s = flip::spatial_filters(kFlipDefaultPixelsPerDegree);
  ASSERT_EQ(s.y.size(), 21u);
  auto sum = [](const std::vector<float>& v) { return std::accumulate(v.begin(), v.end(), 0.0); };
  EXPECT_NEAR(sum(s.y), 1.0, 1e-6);
  EXPECT_NEAR(sum(s.cx), 1.0, 1e-6);
  EXPECT_NEAR(sum(s.cz1) * sum(s.cz1) + sum(s.cz2) * sum(s.cz2), 1.0, 1e-6);  // the 2-D Cz kernel sums to 1
  // Y's Gaussian has a standard deviation of sqrt(0.0047 / (2 pi^2)) degrees = 1.034 pixels at 67.02 ppd:
  // the ratio of neighbouring taps is exp(-1 / (2 sigma^2)).
  const double sigma = std::sqrt(0.0047 / (2 * M_PI * M_PI)) * kFlipDefaultPixelsPerDegree;
  EXPECT_NEAR(s.y[11] / s.y[10], std::exp(-1.0 / (2 * sigma * sigma)), 1e-4);
  const auto f = flip::feature_filters(kFlipDefaultPixelsPerDegree);
  ASSERT_EQ(f.g.size(), 19u);
  EXPECT_NEAR(sum(f.g), 1.0, 1e-6);
  double dg_pos = 0, dg_neg = 0, ddg_pos = 0, ddg_neg = 0;
  for (std::size_t i = 0; i < f.g.size(); ++i) {
    (f.dg[i] > 0 ? dg_pos : dg_neg) += f.dg[i];
    (f.ddg[i] > 0 ? ddg_pos : ddg_neg) += f.ddg[i];
    EXPECT_FLOAT_EQ(f.g[i], f.g[f.g.size() - 1 - i]);     // symmetric
    EXPECT_FLOAT_EQ(f.dg[i], -f.dg[f.g.size() - 1 - i]);  // antisymmetric
  }
  EXPECT_NEAR(dg_pos, 1.0, 1e-6);
  EXPECT_NEAR(dg_neg, -1.0, 1e-6);
  EXPECT_NEAR(ddg_pos, 1.0, 1e-6);
  EXPECT_NEAR(ddg_neg, -1.0, 1e-6);
  EXPECT_GT(f.dg[0], 0.0f);   // -x g is positive left of the centre
  EXPECT_LT(f.ddg[9], 0.0f);  // (x^2 / sigma^2 - 1) g is negative at the centre
}

// --- The whole map -----------------------------------------------------------------------------------------

struct Rgb {
  std::vector<float> r, g, b;
  explicit Rgb(std::size_t n, float v = 0.0f) : r(n, v), g(n, v), b(n, v) {}
  FlipImage image() const { return {r.data(), g.data(), b.data()}; }
};

Rgb random_rgb(std::size_t n, unsigned seed, float hi = 1.0f) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, hi);
  Rgb img(n);
  for (auto* p : {&img.r, &img.g, &img.b})
    for (auto& v : *p) v = u(rng);
  return img;
}

TEST(Flip, IdenticalImagesGiveExactlyZero) {
  const int w = 64, h = 48;
  const Rgb img = random_rgb(std::size_t(w * h), 1, 4.0f);
  for (const FlipRange range : {FlipRange::Ldr, FlipRange::Hdr}) {
    std::vector<float> map(std::size_t(w * h), -1.0f);
    auto s = evaluate_flip(range, img.image(), img.image(), w, h, {}, map.data());
    ASSERT_TRUE(s) << s.error().message;
    EXPECT_EQ(*std::max_element(map.begin(), map.end()), 0.0f);
    EXPECT_EQ(*std::min_element(map.begin(), map.end()), 0.0f);
    EXPECT_EQ(s->mean, 0.0);
    EXPECT_EQ(s->weighted_median, 0.0);
    EXPECT_EQ(s->pixels, std::size_t(w * h));
  }
}

TEST(Flip, UniformGreyDifferenceGivesTheColourPipelineValue) {
  // Uniform images: every filter preserves a constant, and the feature filters give 0 edges and points, so FLIP
  // is the re-mapped HyAB of the two greys: L = 116 y^(1/3) - 16, a = b = 0.
  const int w = 40, h = 30;
  const std::size_t n = std::size_t(w * h);
  const Rgb ref(n, 0.5f), test(n, 0.6f);
  const double hyab = lab_l(0.6) - lab_l(0.5);                             // 5.76891
  const double expected = std::pow(hyab, 0.7) * 0.95 / (0.4 * hand_cmax());  // below the knee: 0.1962
  FlipOptions linear;
  linear.ldr_input = FlipLdrInput::Linear;
  std::vector<float> map(n);
  auto s = evaluate_flip(FlipRange::Ldr, test.image(), ref.image(), w, h, linear, map.data());
  ASSERT_TRUE(s);
  EXPECT_NEAR(s->mean, expected, 5e-4);
  EXPECT_NEAR(map[0], expected, 5e-4);  // corners too: borders are clamped, not dropped
  EXPECT_NEAR(map[n / 2], expected, 5e-4);
  // The same images sRGB-encoded, read as sRGB: the same map up to the float round trip through the sRGB curve
  // (measured 4e-5 here; uniform images are the worst case, their feature term is the square root of rounding).
  auto encode = [](float v) { return 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f; };
  const Rgb ref_s(n, encode(0.5f)), test_s(n, encode(0.6f));
  std::vector<float> map_s(n);
  ASSERT_TRUE(evaluate_flip(FlipRange::Ldr, test_s.image(), ref_s.image(), w, h, {}, map_s.data()));
  for (std::size_t i = 0; i < n; ++i) ASSERT_NEAR(map_s[i], map[i], 1e-4) << i;
}

TEST(Flip, AnEdgeRaisesTheErrorTowardsOne) {
  // A vertical step present in the reference and missing in the test: next to it the feature difference lifts
  // the colour error (FLIP = colour^(1 - feature) >= colour), far from it only the colour error is left.
  const int w = 64, h = 16;
  const std::size_t n = std::size_t(w * h);
  Rgb ref(n, 0.2f), test(n, 0.2f);
  for (int y = 0; y < h; ++y)
    for (int x = w / 2; x < w; ++x) ref.r[std::size_t(y * w + x)] = ref.g[std::size_t(y * w + x)] = ref.b[std::size_t(y * w + x)] = 0.8f;
  std::vector<float> map(n);
  ASSERT_TRUE(evaluate_flip(FlipRange::Ldr, test.image(), ref.image(), w, h, {}, map.data()));
  const float at_edge = map[std::size_t(8 * w + w / 2)], far_right = map[std::size_t(8 * w + w - 1)];
  EXPECT_GT(at_edge, 0.5f);
  EXPECT_GT(at_edge, far_right);
  EXPECT_EQ(map[std::size_t(8 * w)], 0.0f);  // far left: the images agree and no feature is near
}

TEST(Flip, InvalidPixelsAreZeroAndLeftOut) {
  const int w = 32, h = 24;
  const std::size_t n = std::size_t(w * h);
  Rgb ref = random_rgb(n, 2), test = random_rgb(n, 3);
  test.g[100] = std::numeric_limits<float>::quiet_NaN();
  std::vector<std::uint8_t> valid(n, 1);
  valid[100] = 0;
  std::vector<float> map(n);
  FlipEvaluator flip_evaluator;
  ASSERT_TRUE(flip_evaluator.ldr(test.image(), ref.image(), w, h, valid.data(), map.data()));
  EXPECT_EQ(map[100], 0.0f);
  for (float v : map) ASSERT_TRUE(std::isfinite(v));
  const FlipStats all = flip_statistics(map, valid.data());
  EXPECT_EQ(all.pixels, n - 1);
  auto e = flip_evaluator.hdr(test.image(), ref.image(), w, h, valid.data(), map.data());
  ASSERT_TRUE(e) << e.error().message;
  for (float v : map) ASSERT_TRUE(std::isfinite(v));
}

TEST(Flip, GivenExposuresAndExposureMap) {
  const int w = 32, h = 24;
  const std::size_t n = std::size_t(w * h);
  const Rgb ref = random_rgb(n, 4, 8.0f), test = random_rgb(n, 5, 8.0f);
  FlipOptions o;
  o.start_exposure = -2.0f;
  o.stop_exposure = 1.0f;
  o.exposures = 4;
  FlipEvaluator e(o);
  std::vector<float> map(n), exposure(n);
  auto x = e.hdr(test.image(), ref.image(), w, h, nullptr, map.data(), exposure.data());
  ASSERT_TRUE(x) << x.error().message;
  EXPECT_EQ(x->start, -2.0f);
  EXPECT_EQ(x->stop, 1.0f);
  EXPECT_EQ(x->count, 4);
  for (float v : exposure) ASSERT_TRUE(v == 0.0f || v == 1.0f / 3.0f || v == 2.0f / 3.0f || v == 1.0f) << v;
  // HDR-FLIP is the maximum over exposures: at least the LDR-FLIP of the exposure -2 image pair.
  std::vector<float> one(n);
  o.stop_exposure = -2.0f;
  o.exposures = 2;
  ASSERT_TRUE(FlipEvaluator(o).hdr(test.image(), ref.image(), w, h, nullptr, one.data()));
  for (std::size_t i = 0; i < n; ++i) ASSERT_GE(map[i], one[i]) << i;
}

TEST(Flip, BadOptionsAndInputsAreErrors) {
  const Rgb img(16, 0.5f);
  std::vector<float> map(16);
  FlipOptions o;
  o.pixels_per_degree = 0.0;
  EXPECT_EQ(FlipEvaluator(o).ldr(img.image(), img.image(), 4, 4, nullptr, map.data()).error().kind, ErrorKind::Usage);
  // Issue 26 item 8: 1e30 asked for filters of 1e29 taps (a crash); the library accepts [1, 1000] only.
  for (double ppd : {1e30, 1000.5, 0.5}) {
    o.pixels_per_degree = ppd;
    EXPECT_EQ(FlipEvaluator(o).ldr(img.image(), img.image(), 4, 4, nullptr, map.data()).error().kind, ErrorKind::Usage)
        << ppd;
  }
  for (double ppd : {kFlipMinPixelsPerDegree, kFlipMaxPixelsPerDegree}) {
    o.pixels_per_degree = ppd;
    ASSERT_TRUE(FlipEvaluator(o).ldr(img.image(), img.image(), 4, 4, nullptr, map.data())) << ppd;
    for (float v : map) EXPECT_TRUE(std::isfinite(v)) << ppd;
  }
  o = {};
  o.start_exposure = 2.0f;
  o.stop_exposure = 1.0f;
  EXPECT_EQ(FlipEvaluator(o).hdr(img.image(), img.image(), 4, 4, nullptr, map.data()).error().kind, ErrorKind::Usage);
  o = {};
  o.exposures = 1;
  EXPECT_EQ(FlipEvaluator(o).hdr(img.image(), img.image(), 4, 4, nullptr, map.data()).error().kind, ErrorKind::Usage);
  FlipImage missing = img.image();
  missing.g = nullptr;
  EXPECT_EQ(FlipEvaluator().ldr(missing, img.image(), 4, 4, nullptr, map.data()).error().kind, ErrorKind::Input);
  EXPECT_EQ(FlipEvaluator().ldr(img.image(), img.image(), 0, 4, nullptr, map.data()).error().kind, ErrorKind::Input);
}

// --- Pooling -----------------------------------------------------------------------------------------------

TEST(FlipStatistics, WeightedPercentilesByHand) {
  // Sorted 0.1, 0.2, 0.35 (total 0.65), running sums 0.1, 0.3, 0.65: the 0.25 percentile is where the running sum
  // first exceeds 0.1625 (0.2); the median exceeds 0.325 (0.35); so does the 0.75 one (0.4875).
  const std::vector<float> map = {0.35f, 0.1f, 0.9f, 0.2f};
  const std::vector<std::uint8_t> valid = {1, 1, 0, 1};
  const FlipStats s = flip_statistics(map, valid.data());
  EXPECT_EQ(s.pixels, 3u);
  EXPECT_NEAR(s.mean, 0.65 / 3, 1e-7);
  EXPECT_FLOAT_EQ(float(s.weighted_quartile_1), 0.2f);
  EXPECT_FLOAT_EQ(float(s.weighted_median), 0.35f);
  EXPECT_FLOAT_EQ(float(s.weighted_quartile_3), 0.35f);
  EXPECT_FLOAT_EQ(float(s.min), 0.1f);
  EXPECT_FLOAT_EQ(float(s.max), 0.35f);
  const FlipStats none = flip_statistics(map, std::vector<std::uint8_t>(4, 0).data());
  EXPECT_EQ(none.pixels, 0u);
  EXPECT_TRUE(std::isnan(none.mean));
}

TEST(FlipStatistics, MatchesAFullSortOnManyValues) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<float> map(200000);
  for (auto& v : map) v = u(rng) * u(rng) * u(rng);  // crowded near 0, like FLIP maps
  const FlipStats s = flip_statistics(map);
  std::vector<float> sorted = map;
  std::sort(sorted.begin(), sorted.end());
  const double total = std::accumulate(sorted.begin(), sorted.end(), 0.0);
  auto brute = [&](double p) {
    double running = 0.0;
    for (float v : sorted)
      if ((running += v) > p * total) return double(v);
    return 0.0;
  };
  EXPECT_NEAR(s.mean, total / double(map.size()), 1e-12);
  EXPECT_EQ(s.weighted_quartile_1, brute(0.25));
  EXPECT_EQ(s.weighted_median, brute(0.5));
  EXPECT_EQ(s.weighted_quartile_3, brute(0.75));
}

}  // namespace
}  // namespace temporal
