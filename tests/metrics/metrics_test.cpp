// Unit tests of the metric kernels: PSNR, SSIM (against an independent direct computation and hand values),
// the motion-compensated fetch and flicker.
#include "temporal/metrics/flicker.h"
#include "temporal/core/image.h"
#include "temporal/metrics/metrics.h"
#include "temporal/core/reproject.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace temporal {
namespace {

std::vector<float> random_plane(int w, int h, unsigned seed, float lo = 0.0f, float hi = 1.0f) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(lo, hi);
  std::vector<float> p(std::size_t(w) * std::size_t(h));
  for (auto& v : p) v = u(rng);
  return p;
}

// Wang et al. 2004 SSIM at one window, computed directly: the 2-D Gaussian window (not separable passes),
// two-pass mean and (co)variance in double. Independent of the library's implementation.
double direct_ssim_window(const std::vector<float>& x, const std::vector<float>& y, int w, int cx, int cy,
                          double L) {
  const double sigma = 1.5, c1 = (0.01 * L) * (0.01 * L), c2 = (0.03 * L) * (0.03 * L);
  double wsum = 0.0;
  for (int j = -5; j <= 5; ++j)
    for (int i = -5; i <= 5; ++i) wsum += std::exp(-(i * i + j * j) / (2 * sigma * sigma));
  auto weight = [&](int i, int j) { return std::exp(-(i * i + j * j) / (2 * sigma * sigma)) / wsum; };
  double mx = 0, my = 0;
  for (int j = -5; j <= 5; ++j)
    for (int i = -5; i <= 5; ++i) {
      const std::size_t k = std::size_t(cy + j) * std::size_t(w) + std::size_t(cx + i);
      mx += weight(i, j) * x[k];
      my += weight(i, j) * y[k];
    }
  double sxx = 0, syy = 0, sxy = 0;
  for (int j = -5; j <= 5; ++j)
    for (int i = -5; i <= 5; ++i) {
      const std::size_t k = std::size_t(cy + j) * std::size_t(w) + std::size_t(cx + i);
      sxx += weight(i, j) * (x[k] - mx) * (x[k] - mx);
      syy += weight(i, j) * (y[k] - my) * (y[k] - my);
      sxy += weight(i, j) * (x[k] - mx) * (y[k] - my);
    }
  return ((2 * mx * my + c1) * (2 * sxy + c2)) / ((mx * mx + my * my + c1) * (sxx + syy + c2));
}

TEST(Psnr, KnownValuesAndIdentity) {
  // Constant error 0.1 on every channel: MSE = 0.01, PSNR = 10 log10(1 / 0.01) = 20 dB.
  SquaredError e{0.01 * 300, 300};
  EXPECT_NEAR(psnr_db(e, 1.0), 20.0, 1e-12);
  // Peak 2: +20 log10(2) = 6.0206 dB.
  EXPECT_NEAR(psnr_db(e, 2.0), 20.0 + 20.0 * std::log10(2.0), 1e-12);
  // Identical: +inf, never NaN.
  const double inf = psnr_db(SquaredError{0.0, 300}, 1.0);
  EXPECT_TRUE(std::isinf(inf) && inf > 0);
  // Nothing compared: NaN ("no value").
  EXPECT_TRUE(std::isnan(psnr_db(SquaredError{0.0, 0}, 1.0)));
}

TEST(Psnr, SquaredErrorSplitsByMaskAndSkipsInvalid) {
  const int w = 4, h = 2;
  std::vector<float> t(8, 0.5f), r(8, 0.5f), mask(8, 0.0f);
  t[1] = 0.7f;  // error 0.2 inside the mask
  t[6] = 0.1f;  // error 0.4 outside
  t[7] = 9.0f;  // invalid pixel: ignored
  mask[1] = 1.0f;
  std::vector<std::uint8_t> valid(8, 1);
  valid[7] = 0;
  const float* tp = t.data();
  const float* rp = r.data();
  const auto e = squared_error({&tp, 1}, {&rp, 1}, w, h, valid.data(), mask.data());
  EXPECT_EQ(e.all.samples, 7u);
  EXPECT_NEAR(e.all.sum, 0.04 + 0.16, 1e-6);
  EXPECT_EQ(e.inside.samples, 1u);
  EXPECT_NEAR(e.inside.sum, 0.04, 1e-6);
  EXPECT_EQ(e.outside.samples, 6u);
  EXPECT_NEAR(e.outside.sum, 0.16, 1e-6);
}

TEST(Psnr, FiniteMaskCountsNanAndInf) {
  std::vector<float> a = {0.f, NAN, 1.f, INFINITY, 2.f}, b = {0.f, 0.f, -INFINITY, 0.f, 0.f};
  std::vector<std::uint8_t> valid(5);
  const float* ap = a.data();
  const float* bp = b.data();
  EXPECT_EQ(finite_mask({&ap, 1}, {&bp, 1}, 5, valid.data()), 3u);
  EXPECT_EQ(valid, (std::vector<std::uint8_t>{1, 0, 0, 0, 1}));
}

TEST(Psnr, IdiffPeakIsLargestValueAtLeastOne) {
  std::vector<float> a = {0.2f, 0.5f}, b = {0.1f, NAN};
  const float* p[2] = {a.data(), b.data()};
  EXPECT_EQ(idiff_peak(p, 2), 1.0f);
  a[1] = 3.5f;
  EXPECT_EQ(idiff_peak(p, 2), 3.5f);
}

TEST(Ssim, GaussianTapsAreWangWindow) {
  const auto g = ssim_gaussian_taps(1.5, 5);
  ASSERT_EQ(g.size(), 11u);
  double sum = 0;
  for (double v : g) sum += v;
  EXPECT_NEAR(sum, 1.0, 1e-12);
  // Centre tap: 1 / sum_k exp(-k^2 / 4.5), k = -5..5 = 1 / 3.7592... = 0.266011 (hand-computed).
  EXPECT_NEAR(g[5], 0.266011, 1e-6);
  EXPECT_NEAR(g[0] / g[5], std::exp(-25.0 / 4.5), 1e-12);
}

TEST(Ssim, ConstantImagesGiveTheLuminanceTerm) {
  // x = 0.5, y = 0.25 everywhere: all variances are 0, so SSIM = (2 mx my + C1) / (mx^2 + my^2 + C1)
  // = (0.25 + 1e-4) / (0.3125 + 1e-4) = 0.800064 (C1 = (0.01 * 1)^2).
  const int w = 16, h = 13;
  std::vector<float> x(std::size_t(w * h), 0.5f), y(std::size_t(w * h), 0.25f);
  auto r = ssim(x.data(), y.data(), w, h, nullptr, nullptr, SsimOptions{});
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(r->windows, std::size_t((w - 10) * (h - 10)));
  EXPECT_NEAR(r->mean, 0.2501 / 0.3126, 1e-6);
}

TEST(Ssim, MatchesDirectComputationOnEveryWindow) {
  const int w = 19, h = 14;
  const auto x = random_plane(w, h, 1);
  auto y = x;
  const auto noise = random_plane(w, h, 2, -0.2f, 0.2f);
  for (std::size_t i = 0; i < y.size(); ++i) y[i] = 0.8f * y[i] + noise[i];
  double expected = 0.0;
  int windows = 0;
  for (int cy = 5; cy < h - 5; ++cy)
    for (int cx = 5; cx < w - 5; ++cx, ++windows) expected += direct_ssim_window(x, y, w, cx, cy, 1.0);
  expected /= windows;
  std::vector<float> map(x.size(), -1.0f);
  auto r = ssim(x.data(), y.data(), w, h, nullptr, nullptr, SsimOptions{}, map.data());
  ASSERT_TRUE(r);
  EXPECT_EQ(r->windows, std::size_t(windows));
  EXPECT_NEAR(r->mean, expected, 2e-5);
  EXPECT_LT(r->mean, 0.95);  // a real difference, not a trivially perfect score
  // The map holds 1 - SSIM at the window centres, 0 on the border without a full window.
  EXPECT_NEAR(map[std::size_t(7 * w + 9)], 1.0 - direct_ssim_window(x, y, w, 9, 7, 1.0), 2e-5);
  EXPECT_EQ(map[0], 0.0f);
}

TEST(Ssim, SingleWindowElevenByEleven) {
  const int w = 11, h = 11;
  const auto x = random_plane(w, h, 5);
  const auto y = random_plane(w, h, 6);
  auto r = ssim(x.data(), y.data(), w, h, nullptr, nullptr, SsimOptions{});
  ASSERT_TRUE(r);
  EXPECT_EQ(r->windows, 1u);
  EXPECT_NEAR(r->mean, direct_ssim_window(x, y, w, 5, 5, 1.0), 1e-5);
}

TEST(Ssim, PeakScalesTheConstants) {
  // Scaling both images and L by the same factor leaves SSIM unchanged (C1, C2 scale with L^2).
  const int w = 15, h = 15;
  auto x = random_plane(w, h, 7), y = random_plane(w, h, 8);
  auto a = ssim(x.data(), y.data(), w, h, nullptr, nullptr, SsimOptions{});
  for (auto& v : x) v *= 10.0f;
  for (auto& v : y) v *= 10.0f;
  SsimOptions o;
  o.peak = 10.0;
  auto b = ssim(x.data(), y.data(), w, h, nullptr, nullptr, o);
  ASSERT_TRUE(a && b);
  EXPECT_NEAR(a->mean, b->mean, 1e-5);
}

TEST(Ssim, IdenticalIsOneAndNanPixelsAreExcluded) {
  const int w = 20, h = 16;
  auto x = random_plane(w, h, 3);
  auto y = x;
  std::vector<std::uint8_t> valid(x.size(), 1);
  y[std::size_t(8 * w + 9)] = NAN;
  valid[std::size_t(8 * w + 9)] = 0;
  auto r = ssim(x.data(), y.data(), w, h, valid.data(), nullptr, SsimOptions{});
  ASSERT_TRUE(r);
  EXPECT_FALSE(std::isnan(r->mean));
  EXPECT_EQ(r->windows, std::size_t((w - 10) * (h - 10) - 1));  // the window centred on the NaN is skipped
  EXPECT_NEAR(r->mean, 1.0, 1e-6);
}

TEST(Ssim, MaskSplitsByWindowCentre) {
  const int w = 24, h = 12;
  auto x = random_plane(w, h, 11);
  auto y = x;
  std::vector<float> mask(x.size(), 0.0f);
  for (int yy = 0; yy < h; ++yy)
    for (int xx = 12; xx < w; ++xx) {
      mask[std::size_t(yy * w + xx)] = 1.0f;
      y[std::size_t(yy * w + xx)] = 1.0f - x[std::size_t(yy * w + xx)];
    }
  auto r = ssim(x.data(), y.data(), w, h, nullptr, mask.data(), SsimOptions{});
  ASSERT_TRUE(r);
  EXPECT_EQ(r->windows_inside + r->windows_outside, r->windows);
  EXPECT_EQ(r->windows_inside, std::size_t(7 * 2));  // centres x = 12..18, y = 5..6
  EXPECT_GT(r->mean_outside, r->mean_inside + 0.5);
}

TEST(Ssim, TooSmallImageIsAnInputError) {
  std::vector<float> x(100, 0.5f);
  auto r = ssim(x.data(), x.data(), 10, 10, nullptr, nullptr, SsimOptions{});
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().kind, ErrorKind::Input);
}

// The motion-compensated fetch of the flicker metric: the shared reprojection (temporal/core/reproject.h).
void warp_bilinear(const float* prev, int w, int h, const float* mx, const float* my, float* out) {
  reproject::Frames fr;
  fr.width = w;
  fr.height = h;
  fr.motion_x = mx;
  fr.motion_y = my;
  const float* p[] = {prev};
  float* o[] = {out};
  reproject::warp_planes(fr, p, o);
}

TEST(Warp, FollowsConventionSignAndMarksOutside) {
  const int w = 5, h = 3;
  std::vector<float> prev(15);
  for (int i = 0; i < 15; ++i) prev[std::size_t(i)] = float(i);
  // motion = (+1, 0): p_prev = p + (1, 0), so out(x, y) = prev(x + 1, y); the last column falls outside.
  std::vector<float> mx(15, 1.0f), my(15, 0.0f), out(15);
  warp_bilinear(prev.data(), w, h, mx.data(), my.data(), out.data());
  EXPECT_EQ(out[0], 1.0f);
  EXPECT_EQ(out[7], 8.0f);
  EXPECT_TRUE(std::isnan(out[4]));
  // Half a pixel up and left: mean of the four neighbours ((0,0),(1,0),(0,1),(1,1)) at pixel (1,1).
  std::fill(mx.begin(), mx.end(), -0.5f);
  std::fill(my.begin(), my.end(), -0.5f);
  warp_bilinear(prev.data(), w, h, mx.data(), my.data(), out.data());
  EXPECT_NEAR(out[6], (0.0f + 1.0f + 5.0f + 6.0f) / 4.0f, 1e-6);
  // Within half a pixel of the border: clamped to the edge pixel, not outside.
  EXPECT_NEAR(out[0], 0.0f, 1e-6);
  // No motion: a plain copy.
  warp_bilinear(prev.data(), w, h, nullptr, nullptr, out.data());
  EXPECT_EQ(out, prev);
}

TEST(Flicker, IdenticalIsZeroAlternatingErrorIsTwiceIt) {
  const int w = 8, h = 4;
  const std::size_t n = 32;
  std::vector<float> r0 = random_plane(w, h, 1), r1 = random_plane(w, h, 2);
  std::vector<float> rd(n), td(n);
  temporal_delta(r1.data(), r0.data(), n, rd.data());
  // Test identical to the reference: 0 exactly.
  auto same = flicker(rd.data(), rd.data(), w, h, nullptr, nullptr);
  EXPECT_EQ(same.pixels, n);
  EXPECT_EQ(same.rms(), 0.0);
  // Test = reference + e at frame 0 and - e at frame 1: d = -2e everywhere, RMS 2e.
  const float e = 0.05f;
  std::vector<float> t0(n), t1(n);
  for (std::size_t i = 0; i < n; ++i) {
    t0[i] = r0[i] + e;
    t1[i] = r1[i] - e;
  }
  temporal_delta(t1.data(), t0.data(), n, td.data());
  auto f = flicker(td.data(), rd.data(), w, h, nullptr, nullptr);
  EXPECT_NEAR(f.rms(), 2 * e, 1e-6);
}

TEST(Flicker, MotionCompensationRemovesErrorThatMovesWithTheSurface) {
  // A texture moving right by 1 pixel per frame; the test carries a fixed error pattern on the moving surface
  // (stable, no flicker). Motion vectors (-1, 0) point back to where each surface point was.
  const int w = 32, h = 8;
  const std::size_t n = std::size_t(w * h);
  const auto tex = random_plane(64, 1, 9);
  const auto err = random_plane(64, 1, 10, -0.1f, 0.1f);
  auto frame = [&](int t, bool with_error) {
    std::vector<float> img(n);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const int u = x - t + 8;  // surface coordinate
        img[std::size_t(y * w + x)] = tex[std::size_t(u)] + (with_error ? err[std::size_t(u)] : 0.0f);
      }
    return img;
  };
  const auto r0 = frame(0, false), r1 = frame(1, false), t0 = frame(0, true), t1 = frame(1, true);
  std::vector<float> mx(n, -1.0f), my(n, 0.0f), warped(n), rd(n), td(n);
  warp_bilinear(r0.data(), w, h, mx.data(), my.data(), warped.data());
  temporal_delta(r1.data(), warped.data(), n, rd.data());
  warp_bilinear(t0.data(), w, h, mx.data(), my.data(), warped.data());
  temporal_delta(t1.data(), warped.data(), n, td.data());
  auto compensated = flicker(td.data(), rd.data(), w, h, nullptr, nullptr);
  EXPECT_EQ(compensated.pixels, n - std::size_t(h));  // column 0 came from outside the image
  EXPECT_NEAR(compensated.rms(), 0.0, 1e-6);
  // Without motion vectors the moving error pattern reads as change at every pixel.
  temporal_delta(r1.data(), r0.data(), n, rd.data());
  temporal_delta(t1.data(), t0.data(), n, td.data());
  auto plain = flicker(td.data(), rd.data(), w, h, nullptr, nullptr);
  EXPECT_GT(plain.rms(), 0.02);
}

TEST(Flicker, MaskAndNanHandling) {
  const int w = 4, h = 1;
  std::vector<float> td = {0.1f, 0.2f, NAN, 0.3f}, rd = {0.f, 0.f, 0.f, 0.f}, mask = {1, 0, 1, 0}, map(4);
  auto f = flicker(td.data(), rd.data(), w, h, nullptr, mask.data(), map.data());
  EXPECT_EQ(f.pixels, 3u);
  EXPECT_NEAR(f.rms_inside(), 0.1, 1e-6);
  EXPECT_NEAR(f.rms_outside(), std::sqrt((0.04 + 0.09) / 2.0), 1e-6);
  EXPECT_EQ(map[2], 0.0f);
  EXPECT_NEAR(map[3], 0.3f, 1e-6);
}

TEST(Channels, ComparedChannelOrder) {
  Image img(2, 2);
  for (const char* c : {"B", "R", "A", "G", "albedo.B", "albedo.R", "albedo.G", "debug.mask", "debug.alpha"})
    img.add_channel(c);
  EXPECT_EQ(compared_channels(img, "rgb"), (std::vector<std::string>{"R", "G", "B"}));
  EXPECT_EQ(compared_channels(img, "albedo"), (std::vector<std::string>{"albedo.R", "albedo.G", "albedo.B"}));
  EXPECT_EQ(compared_channels(img, "debug.mask"), (std::vector<std::string>{"debug.mask"}));
  EXPECT_TRUE(compared_channels(img, "N").empty());
}

TEST(Luminance, Rec709WeightsForThreeChannels) {
  std::vector<float> r = {1, 0}, g = {0, 1}, b = {0, 0}, out(2);
  const float* p[3] = {r.data(), g.data(), b.data()};
  luminance_plane(p, 2, out.data());
  EXPECT_NEAR(out[0], 0.2126f, 1e-7);
  EXPECT_NEAR(out[1], 0.7152f, 1e-7);
  const float* one[1] = {g.data()};
  luminance_plane(one, 2, out.data());
  EXPECT_EQ(out[1], 1.0f);
}

}  // namespace
}  // namespace temporal
