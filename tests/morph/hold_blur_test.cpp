// Hold-type blur under smooth pursuit (seed 004 section 3).
#include "temporal/morph/hold_blur.h"
#include "temporal/morph/methods.h"
#include "temporal/morph/morph.h"

#include "synthetic.h"

#include <gtest/gtest.h>

#include <cmath>

namespace temporal::morph {
namespace {

// A vertical step edge at x = edge (0 left, 1 right), all channels.
Image step(int w, int h, float edge) {
  return test::make_color(w, h, [=](float x, float, int) { return x >= edge ? 1.0f : 0.0f; });
}

int ramp_width(const Image& p, int row) {
  int n = 0;
  const float* r = p.plane("G") + row * p.width();
  for (int x = 0; x < p.width(); ++x) n += r[x] > 0.05f && r[x] < 0.95f;
  return n;
}

TEST(HoldBlur, StaticImageIsPerceivedUnchanged) {
  const int w = 40, h = 20;
  Image a = test::make_color(w, h, [](float x, float y, int c) { return test::texture(x, y, c); });
  std::vector<float> zero(a.pixel_count(), 0.0f);
  const Image* frames[3] = {&a, &a, &a};
  auto p = perceive_hold(frames, {"R", "G", "B"}, zero.data(), zero.data());
  ASSERT_TRUE(p);
  for (std::size_t i = 0; i < a.pixel_count(); ++i) ASSERT_NEAR(p->plane("R")[i], a.plane("R")[i], 1e-6f);
}

TEST(HoldBlur, HeldFramesBlurThreeTimesMoreThanNativeFrames) {
  const int w = 96, h = 8;
  const float v = 4.0f;  // the edge moves 4 px right per displayed frame: motion = -4
  std::vector<float> mx(std::size_t(w) * h, -v), my(std::size_t(w) * h, 0.0f);
  Image f0 = step(w, h, 40.0f), f1 = step(w, h, 44.0f), f2 = step(w, h, 48.0f);
  const Image* native[3] = {&f0, &f1, &f2};
  const Image* held[3] = {&f0, &f0, &f0};  // `repeat`: one rendered frame held for three display frames
  auto pn = perceive_hold(native, {"R", "G", "B"}, mx.data(), my.data());
  auto ph = perceive_hold(held, {"R", "G", "B"}, mx.data(), my.data());
  ASSERT_TRUE(pn);
  ASSERT_TRUE(ph);
  // Native: box of |v| = 4 px (plus one pixel of bilinear ramp); held: box of 3 |v| = 12 px.
  EXPECT_GE(ramp_width(*pn, 4), 3);
  EXPECT_LE(ramp_width(*pn, 4), 5);
  EXPECT_GE(ramp_width(*ph, 4), 9);
  EXPECT_LE(ramp_width(*ph, 4), 13);
  // Energy is conserved: the sum over the row equals the integral of the moving step seen by the eye:
  // the native edge stays at retinal x = 40 - 4 s on average over each frame, the held one drifts.
  double sn = 0.0;
  for (int x = 0; x < w; ++x) sn += pn->plane("G")[4 * w + x];
  EXPECT_NEAR(sn, double(w) - 40.0 + 2.0, 0.05);  // centre of the native ramp at 40 - v/2
}

TEST(HoldBlur, BadInput) {
  Image a = step(16, 8, 4.0f), b = step(8, 8, 4.0f);
  std::vector<float> m(a.pixel_count(), 0.0f);
  const Image* frames[2] = {&a, &b};
  EXPECT_FALSE(perceive_hold(frames, {"R"}, m.data(), m.data()));
  const Image* one[1] = {&a};
  EXPECT_FALSE(perceive_hold(one, {"depth.Z"}, m.data(), m.data()));
  EXPECT_FALSE(perceive_hold(one, {"R"}, nullptr, m.data()));
}

}  // namespace
}  // namespace temporal::morph

namespace temporal::morph {
namespace {

// Seed 004's claim on a synthetic pan: what a tracking eye sees of `didyk` (40 -> 120 Hz) is closer to the
// native 120 Hz stream than the held 40 Hz frames.
TEST(HoldBlur, DidykIsPerceivedCloserToNative120HzThanRepeat) {
  const int w = 96, h = 48;
  const float v120 = 2.0f;  // px per 120 Hz frame: 6 px per rendered 40 Hz frame
  auto frame120 = [&](int j) {
    return test::make_color(w, h, [&](float x, float y, int c) { return test::texture(x - v120 * float(j), y, c); });
  };
  Image native[3] = {frame120(3), frame120(4), frame120(5)};
  Image rendered = frame120(3);  // 40 Hz frame 1 = 120 Hz frame 3
  Image gb40 = test::make_gbuffer(w, h, [&](int, int, float& mx, float& my, float& d) { mx = -3.0f * v120; my = 0.0f; d = 3.0f; });
  MorphOptions o;
  // The paper's interleaving of a sharpened and blurred frames, everywhere.
  ASSERT_TRUE(apply_args(params(o), {"--min-blur", "1"}));
  Morpher m(o);
  std::vector<Image> slots;
  ASSERT_TRUE(m.process(rendered, &gb40, nullptr, slots));
  std::vector<float> mx(rendered.pixel_count(), -v120), my(rendered.pixel_count(), 0.0f);
  const std::vector<std::string> rgb = {"R", "G", "B"};
  const Image* wn[3] = {&native[0], &native[1], &native[2]};
  const Image* wr[3] = {&rendered, &rendered, &rendered};
  const Image* wd[3] = {&slots[0], &slots[1], &slots[2]};
  auto pn = perceive_hold(wn, rgb, mx.data(), my.data());
  auto pr = perceive_hold(wr, rgb, mx.data(), my.data());
  auto pd = perceive_hold(wd, rgb, mx.data(), my.data());
  ASSERT_TRUE(pn && pr && pd);
  double er = 0.0, ed = 0.0;
  for (int y = 16; y < h - 16; ++y)
    for (int x = 24; x < w - 24; ++x)
      for (const auto& c : rgb) {
        const std::size_t i = std::size_t(y) * w + x;
        er += std::abs(pr->plane(c)[i] - pn->plane(c)[i]);
        ed += std::abs(pd->plane(c)[i] - pn->plane(c)[i]);
      }
  EXPECT_LT(ed, 0.5 * er) << "didyk " << ed << " vs repeat " << er;
}

// align_lag (the lag apart from the blur): a bump moving right one pixel per frame (motion.X = -1). An image
// that shows it `lag` frames late has it `lag` pixels to the left; the best shift along the motion is the lag.
Image bump(int w, int h, float centre) {
  return test::make_color(w, h, [=](float x, float, int c) {
    const float d = (x - centre) / 3.0f;
    return (0.2f + 0.1f * float(c)) * std::exp(-0.5f * d * d);
  });
}

TEST(LagAlignment, BestShiftAlongTheMotionIsTheLag) {
  const int w = 64, h = 4;
  std::vector<float> mx(std::size_t(w) * h, -1.0f), my(std::size_t(w) * h, 0.0f);
  const Image reference = bump(w, h, 32.5f);
  // Two frames late: the bump is 2 px left. P_method(r) = P_native(r + tau u), u = 1: tau = 2, exact on the
  // coarse grid (0.25 frames), and the shifted image matches the reference to rounding.
  auto a = align_lag(bump(w, h, 30.5f), reference, {"R", "G", "B"}, mx.data(), my.data());
  ASSERT_TRUE(a) << a.error().message;
  EXPECT_NEAR(a->lag_frames, 2.0, 1e-9);
  EXPECT_LT(a->mse, 1e-12);
  EXPECT_GT(a->mse_unaligned, 1e-4);  // unaligned, the lag is charged as error
  for (std::size_t i = 0; i < reference.pixel_count(); ++i)
    ASSERT_NEAR(a->aligned.plane("B")[i], reference.plane("B")[i], 1e-6f) << i;
  // Ahead by 1.25 frames: tau = -1.25 (on the grid too).
  a = align_lag(bump(w, h, 33.75f), reference, {"R", "G", "B"}, mx.data(), my.data());
  ASSERT_TRUE(a);
  EXPECT_NEAR(a->lag_frames, -1.25, 1e-9);
  // 0.4 frames late: between coarse candidates; the fine pass (1/32 frame) lands within half a step of 0.4,
  // up to the bilinear fetch's error on a 3-px bump.
  a = align_lag(bump(w, h, 32.1f), reference, {"R", "G", "B"}, mx.data(), my.data());
  ASSERT_TRUE(a);
  EXPECT_NEAR(a->lag_frames, 0.4, 1.0 / 32.0);
}

TEST(LagAlignment, WithoutMotionThereIsNoLag) {
  const int w = 40, h = 6;
  std::vector<float> zero(std::size_t(w) * h, 0.0f);
  // Different images, but no shift along a zero motion changes anything: every tau ties and 0 wins.
  auto a = align_lag(bump(w, h, 10.0f), bump(w, h, 20.0f), {"R", "G", "B"}, zero.data(), zero.data());
  ASSERT_TRUE(a);
  EXPECT_EQ(a->lag_frames, 0.0);
  EXPECT_EQ(a->mse, a->mse_unaligned);
  auto bad = align_lag(bump(w, h, 10.0f), bump(w + 1, h, 10.0f), {"R"}, zero.data(), zero.data());
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().kind, ErrorKind::Input);
}

}  // namespace
}  // namespace temporal::morph
