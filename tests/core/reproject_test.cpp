// The reprojection module (temporal/core/reproject.h): the one off-screen rule, the bilinear taps, the
// disocclusion test and the row kernel, on hand-made images with hand-computed values.
#include "temporal/core/reproject.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

namespace rp = temporal::reproject;

TEST(Reproject, OffScreenRuleIsThePixelArea) {
  // Pixel-index coordinates: the centre of pixel 0 is 0, the image area is [-0.5, W - 0.5).
  EXPECT_TRUE(rp::on_screen(-0.5f, 0.0f, 4, 3));
  EXPECT_FALSE(rp::on_screen(-0.5001f, 0.0f, 4, 3));
  EXPECT_TRUE(rp::on_screen(3.499f, 2.499f, 4, 3));
  EXPECT_FALSE(rp::on_screen(3.5f, 0.0f, 4, 3));
  EXPECT_FALSE(rp::on_screen(0.0f, 2.5f, 4, 3));
  EXPECT_FALSE(rp::on_screen(NAN, 0.0f, 4, 3));
}

TEST(Reproject, BilinearWeightsAndEdgeRepeat) {
  const auto b = rp::bilinear(1.25f, 0.5f, 4, 3);  // taps (1,0) (2,0) (1,1) (2,1)
  EXPECT_EQ(b.i00, 1u);
  EXPECT_EQ(b.i10, 2u);
  EXPECT_EQ(b.i01, 5u);
  EXPECT_EQ(b.i11, 6u);
  EXPECT_FLOAT_EQ(b.w00, 0.75f * 0.5f);
  EXPECT_FLOAT_EQ(b.w10, 0.25f * 0.5f);
  EXPECT_FLOAT_EQ(b.w01, 0.75f * 0.5f);
  EXPECT_FLOAT_EQ(b.w11, 0.25f * 0.5f);
  const float plane[] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11};
  EXPECT_FLOAT_EQ(b(plane), 3.25f);  // x 1.25 + 4 * y 0.5
  // Half a pixel outside the left edge: the outside taps repeat column 0.
  EXPECT_FLOAT_EQ(rp::bilinear(-0.4f, 1.0f, 4, 3)(plane), 4.0f);
  // Exactly at a centre: that pixel, bit for bit.
  EXPECT_EQ(rp::bilinear(2.0f, 2.0f, 4, 3)(plane), 10.0f);
}

TEST(Reproject, CatmullRomWeightsSumToOneAndInterpolate) {
  float w[4];
  rp::catmull_rom_weights(0.0f, w);
  EXPECT_FLOAT_EQ(w[0], 0.0f);
  EXPECT_FLOAT_EQ(w[1], 1.0f);
  rp::catmull_rom_weights(0.5f, w);
  EXPECT_FLOAT_EQ(w[0], -0.0625f);
  EXPECT_FLOAT_EQ(w[1], 0.5625f);
  EXPECT_FLOAT_EQ(w[0] + w[1] + w[2] + w[3], 1.0f);
}

TEST(Reproject, SameSurfaceIsRelativeToTheLargerDepth) {
  const rp::SurfaceTest t;  // 5 %, ids compared
  EXPECT_TRUE(rp::same_surface(10.0f, 3, 10.4f, 3, t));   // 0.4 / 10.4 = 3.8 %
  EXPECT_FALSE(rp::same_surface(10.0f, 3, 10.6f, 3, t));  // 0.6 / 10.6 = 5.7 %
  EXPECT_FALSE(rp::same_surface(10.0f, 3, 10.0f, 4, t));  // contact point: another material
  EXPECT_TRUE(rp::same_surface(10.0f, 3, 10.0f, 4, rp::SurfaceTest{0.05f, false}));
}

namespace {
// A 6x4 previous frame: depth 10 on the left half (id 1), 20 on the right half (id 2); values = x + 10 y.
struct Prev {
  int w = 6, h = 4;
  std::vector<float> z, value;
  std::vector<std::uint32_t> id;
  Prev() {
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        z.push_back(x < 3 ? 10.0f : 20.0f);
        id.push_back(x < 3 ? 1u : 2u);
        value.push_back(float(x + 10 * y));
      }
  }
};
}  // namespace

TEST(Reproject, RowKernelDropsTheTapsOfAnotherSurface) {
  Prev p;
  // Current frame: every pixel moved half a pixel right (motion -0.5: it came from x - 0.5), all at depth 10.
  std::vector<float> mx(24, -0.5f), my(24, 0.0f), z(24, 10.0f);
  std::vector<std::uint32_t> id(24, 1u);
  rp::Frames fr{p.w, p.h, mx.data(), my.data(), z.data(), id.data(), p.z.data(), p.id.data(), {}};
  rp::HistoryRow h;
  rp::reproject_row(fr, 1, h);
  std::vector<float> out(6);
  const float* prev[] = {p.value.data()};
  float* o[] = {out.data()};
  rp::gather_row(h, prev, o, 1, p.w);
  // x = 2: taps (1,1) and (2,1), both the near surface: (11 + 12) / 2.
  EXPECT_EQ(h.hit[2], 1.0f);
  EXPECT_FLOAT_EQ(out[2], 11.5f);
  // x = 3: taps (2,1) near and (3,1) far: the far tap is dropped, the near one renormalised to weight 1.
  EXPECT_EQ(h.hit[3], 1.0f);
  EXPECT_FLOAT_EQ(out[3], 12.0f);
  // x = 5: taps (4,1), (5,1): both far (depth 20 vs 10: 50 % > 5 %, and another id): disoccluded.
  EXPECT_EQ(h.hit[5], 0.0f);
  EXPECT_EQ(out[5], 0.0f);
  // x = 0: position -0.5 is on the edge of the area: the outside tap is dropped, pixel 0 kept.
  EXPECT_EQ(h.hit[0], 1.0f);
  EXPECT_FLOAT_EQ(out[0], 10.0f);
}

TEST(Reproject, RowKernelOffScreenAndNonFiniteMotionMiss) {
  Prev p;
  std::vector<float> mx(24, -0.6f), my(24, 0.0f);
  mx[6 + 3] = NAN;
  mx[6 + 4] = 1e30f;
  rp::Frames fr{p.w, p.h, mx.data(), my.data(), nullptr, nullptr, nullptr, nullptr, {}};  // no depth: area rule only
  rp::HistoryRow h;
  rp::reproject_row(fr, 1, h);
  EXPECT_EQ(h.hit[0], 0.0f);  // position -0.6: outside the image area
  EXPECT_EQ(h.hit[1], 1.0f);
  EXPECT_EQ(h.hit[3], 0.0f);  // NaN motion
  EXPECT_EQ(h.hit[4], 0.0f);  // absurd motion
  EXPECT_EQ(h.hit[5], 1.0f);  // no depth: the far surface is not tested
}

TEST(Reproject, WarpPlanesIsNaNWhereTheFetchMisses) {
  Prev p;
  std::vector<float> mx(24, 0.0f), my(24, -1.0f), z(24, 10.0f), out(24);
  std::vector<std::uint32_t> id(24, 1u);
  rp::Frames fr{p.w, p.h, mx.data(), my.data(), z.data(), id.data(), p.z.data(), p.id.data(), {}};
  const float* prev[] = {p.value.data()};
  float* o[] = {out.data()};
  rp::warp_planes(fr, prev, o);
  EXPECT_TRUE(std::isnan(out[0]));   // row 0 came from row -1: off screen
  EXPECT_FLOAT_EQ(out[6 + 1], 1.0f);  // (1, 1) came from (1, 0)
  EXPECT_TRUE(std::isnan(out[6 + 4]));  // the right half is another surface
  // Without motion and geometry the warp is the identity.
  rp::Frames still{p.w, p.h, nullptr, nullptr, nullptr, nullptr, nullptr, nullptr, {}};
  rp::warp_planes(still, prev, o);
  for (int i = 0; i < 24; ++i) EXPECT_EQ(out[i], p.value[i]);
}
