// Grid morphing (seed 004 sections 5-6) against analytically known in-between frames, and the baselines.
#include "temporal/morph/grid_warp.h"
#include "temporal/morph/methods.h"
#include "temporal/morph/morph.h"

#include "synthetic.h"

#include <gtest/gtest.h>

#include <cmath>

namespace temporal::morph {
namespace {

struct ErrorStats {
  double mean = 0.0, max = 0.0;
};

// Error of `a` (R,G,B) against expected(x, y, c) over the pixels where include(x, y) holds.
template <typename Expected, typename Include>
ErrorStats error(const Image& a, Expected expected, Include include) {
  ErrorStats s;
  std::size_t n = 0;
  const char* names[3] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c) {
    const float* p = a.plane(names[c]);
    for (int y = 0; y < a.height(); ++y)
      for (int x = 0; x < a.width(); ++x) {
        if (!include(x, y)) continue;
        const double e = std::abs(double(p[y * a.width() + x]) - double(expected(x, y, c)));
        s.mean += e;
        s.max = std::max(s.max, e);
        ++n;
      }
  }
  s.mean /= double(std::max<std::size_t>(n, 1));
  return s;
}

TEST(Didyk, CameraTranslationMatchesAnalyticallyShiftedInBetweenFrames) {
  const int w = 96, h = 64, n = 3;
  // The plane's content moves by (+3, +1.5) pixels per rendered frame: motion = (-3, -1.5) (p_prev = p + motion).
  const float vx = 3.0f, vy = 1.5f;
  Image color = test::make_color(w, h, [](float x, float y, int c) { return test::texture(x, y, c); });
  Image gb = test::make_gbuffer(w, h, [&](int, int, float& mx, float& my, float& d) {
    mx = -vx;
    my = -vy;
    d = 4.0f;
  });
  MorphOptions o;
  o.factor = n;
  Morpher m(o);
  std::vector<Image> out;
  MorphTimings t;
  ASSERT_TRUE(m.process(color, &gb, nullptr, out, &t));
  ASSERT_EQ(out.size(), 3u);
  EXPECT_GT(t.total_ms(), 0.0);
  // Border vertices are fixed (section 5.1), so the outer cells stretch: compare away from the border.
  const int margin = 24;
  auto interior = [&](int x, int y) { return x >= margin && y >= margin && x < w - margin && y < h - margin; };
  // Slot 0 is the rendered frame; with no distortion there is no blur to compensate in the interior.
  const auto e0 = error(out[0], [&](int x, int y, int c) { return test::texture(x + 0.5f, y + 0.5f, c); }, interior);
  EXPECT_LT(e0.max, 1e-5);
  for (int k = 1; k < n; ++k) {
    const float tt = float(k) / float(n);
    auto expected = [&](int x, int y, int c) { return test::texture(x + 0.5f - tt * vx, y + 0.5f - tt * vy, c); };
    const auto e = error(out[std::size_t(k)], expected, interior);
    const auto rep = error(color, expected, interior);  // what `repeat` shows
    // Bilinear resampling at a half-pixel offset of a texture with ~10 px wavelength: <= 0.01.
    EXPECT_LT(e.max, 0.012) << "slot " << k;
    EXPECT_LT(e.mean, 0.006) << "slot " << k;
    EXPECT_LT(e.mean, 0.1 * rep.mean) << "slot " << k << ": repeat's mean error " << rep.mean;
  }
}

// Background texture at depth 10, static; an opaque square at depth 2 moving right by `speed` px per frame.
struct Occluder {
  int w = 128, h = 96;
  int x0 = 32, y0 = 24, x1 = 80, y1 = 72;  // square [x0, x1) x [y0, y1)
  float speed = 30.0f, speed_y = 0.0f;
  static float fg(float x, float y, int c) { return 0.9f - 0.4f * (test::texture(y, x, c) - 0.35f); }
  bool inside(float x, float y) const { return x >= x0 && x < x1 && y >= y0 && y < y1; }
  Image color() const {
    return test::make_color(w, h, [&](float x, float y, int c) { return inside(x, y) ? fg(x, y, c) : test::texture(x, y, c); });
  }
  Image gbuffer() const {
    return test::make_gbuffer(w, h, [&](int x, int y, float& mx, float& my, float& d) {
      const bool in = inside(float(x) + 0.5f, float(y) + 0.5f);
      mx = in ? -speed : 0.0f;
      my = in ? -speed_y : 0.0f;
      d = in ? 2.0f : 10.0f;
    });
  }
};

TEST(Didyk, DepthTestKeepsTheOccluderInFront) {
  Occluder s;
  Image color = s.color(), gb = s.gbuffer();
  // Slot 2 of 3: the square moved 20 px right, over background vertices (fold-overs).
  GridOptions go;
  GridBuilder builder;
  SnappedGrid grid;
  builder.build(gb.plane("motion.X"), gb.plane("motion.Y"), gb.plane("depth.Z"), s.w, s.h, go, grid);
  std::vector<float> tx, ty;
  extrapolate_vertices(grid, 2.0f / 3.0f, tx, ty);
  const std::size_t np = color.pixel_count();
  std::vector<float> ones(std::size_t(grid.vertex_count()), 1.0f), coverage(np, 0.0f);
  auto draw = [&](bool depth_test) {
    std::vector<float> r(np, -1.0f);
    const float* src[1] = {color.plane("R")};
    float* dst[1] = {r.data()};
    const float* attr[1] = {ones.data()};
    float* attr_out[1] = {coverage.data()};
    GridRaster raster;
    raster.source = src;
    raster.target = dst;
    raster.attributes = attr;
    raster.attr_target = attr_out;  // 1 where a triangle covers the pixel, 0 (attr_uncovered default) elsewhere
    raster.source_depth = depth_test ? gb.plane("depth.Z") : nullptr;
    GridRasterizer rz;
    rz.draw(grid, tx, ty, raster);
    return r;
  };
  const auto with = draw(true);
  double covered_with = 0.0;
  for (float c : coverage) covered_with += c;
  const auto without = draw(false);
  int wrong_with = 0, wrong_without = 0;
  for (int y = s.y0 + 1; y < s.y1 - 1; ++y)
    for (int x = s.x0 + 21; x < s.x1 + 19; ++x) {
      const float e = Occluder::fg(x + 0.5f - 20.0f, y + 0.5f, 0);
      const std::size_t i = std::size_t(y) * s.w + x;
      wrong_with += std::abs(with[i] - e) > 0.02f;
      wrong_without += std::abs(without[i] - e) > 0.02f;
    }
  EXPECT_NEAR(covered_with, double(np), 1e-3) << "the border-fixed grid must cover every pixel";
  EXPECT_EQ(wrong_with, 0) << "the moved square must be in front everywhere";
  EXPECT_GT(wrong_without, 100) << "without the depth test the later-drawn background covers the square";

  // The full method: the square's inner part (one cell from its edges, where no blur reaches) is exact.
  MorphOptions o;
  Morpher m(o);
  std::vector<Image> out;
  ASSERT_TRUE(m.process(color, &gb, nullptr, out));
  const auto e = error(out[2], [&](int x, int y, int c) { return Occluder::fg(x + 0.5f - 20.0f, y + 0.5f, c); },
                       [&](int x, int y) { return x >= s.x0 + 20 + 8 && x < s.x1 + 20 - 8 && y >= s.y0 + 8 && y < s.y1 - 8; });
  EXPECT_LT(e.max, 0.01);
}

TEST(Didyk, SnappingToTheMotionDiscontinuityReducesTearing) {
  Occluder s;
  s.x0 = 27; s.x1 = 69; s.y0 = 21; s.y1 = 61;  // edges between grid lines
  s.speed = 9.0f; s.speed_y = 3.0f;            // 3 px right, 1 px down per slot
  Image color = s.color(), gb = s.gbuffer();
  auto run = [&](bool snap) {
    MorphOptions o;
    if (!snap) {
      EXPECT_TRUE(apply_args(params(o), {"--no-snap"}));  // didyk's own parameter (DidykOptions)
    }
    Morpher m(o);
    std::vector<Image> out;
    EXPECT_TRUE(m.process(color, &gb, nullptr, out));
    return out;
  };
  const auto snapped = run(true), regular = run(false);
  double obj_snap = 0.0, obj_reg = 0.0;
  int tear_snap = 0, tear_reg = 0;
  for (int k = 1; k < 3; ++k) {
    const float dx = 3.0f * k, dy = 1.0f * k;
    auto expected = [&](int x, int y, int c) {
      const float px = x + 0.5f, py = y + 0.5f;
      return s.inside(px - dx, py - dy) ? Occluder::fg(px - dx, py - dy, c) : test::texture(px, py, c);
    };
    // Tearing shows on the moving object: a cell that straddles its silhouette smears it. Measured on the
    // pixels where the moved object is.
    auto on_object = [&](int x, int y) { return s.inside(x + 0.5f - dx, y + 0.5f - dy); };
    obj_snap += error(snapped[std::size_t(k)], expected, on_object).mean;
    obj_reg += error(regular[std::size_t(k)], expected, on_object).mean;
    // Whole image, except the disoccluded pixels (covered by the square in the rendered frame, uncovered
    // now: unknown to any extrapolation): count gross errors (> 0.2, a torn edge).
    for (int y = 0; y < s.h; ++y)
      for (int x = 0; x < s.w; ++x) {
        const float px = x + 0.5f, py = y + 0.5f;
        if (s.inside(px, py) && !s.inside(px - dx, py - dy)) continue;
        const float e = expected(x, y, 0);
        tear_snap += std::abs(snapped[std::size_t(k)].plane("R")[y * s.w + x] - e) > 0.2f;
        tear_reg += std::abs(regular[std::size_t(k)].plane("R")[y * s.w + x] - e) > 0.2f;
      }
  }
  // Measured: object error 0.032 snapped vs 0.139 regular; gross errors 109 vs 338 pixels.
  EXPECT_LT(obj_snap, 0.4 * obj_reg) << "snapped " << obj_snap << " vs regular " << obj_reg;
  EXPECT_LT(tear_snap, tear_reg / 2) << "snapped " << tear_snap << " vs regular " << tear_reg;
}

TEST(Didyk, SnapsVerticesOntoTheDiscontinuity) {
  Occluder s;
  s.x0 = 27; s.x1 = 69; s.y0 = 21; s.y1 = 61;
  s.speed = 9.0f;
  Image gb = s.gbuffer();
  GridBuilder b;
  SnappedGrid g;
  b.build(gb.plane("motion.X"), gb.plane("motion.Y"), gb.plane("depth.Z"), s.w, s.h, GridOptions{}, g);
  // Vertex (24, 32) (i = 3, j = 4): its block x in [20, 28) holds the left edge (pixel corner x = 27).
  const std::size_t v = std::size_t(4 * g.nx + 3);
  EXPECT_EQ(g.x[v], 27.0f);
  EXPECT_EQ(g.y[v], 32.0f);  // ties along the edge resolve to the nearest point
  EXPECT_FLOAT_EQ(g.mx[v], -9.0f);  // on the corner between square and background it follows the square
  // A vertex far from any edge stays regular and still.
  const std::size_t far = std::size_t(10 * g.nx + 14);
  EXPECT_EQ(g.x[far], 112.0f);
  EXPECT_EQ(g.mx[far], 0.0f);
  // Border vertices never move.
  EXPECT_EQ(g.x[0], 0.0f);
  EXPECT_EQ(g.x[std::size_t(g.nx - 1)], float(s.w));
}

TEST(Didyk, AnyCellSizeAndImageSizeNotAMultipleOfTheCell) {
  const int w = 75, h = 53;  // not multiples of any cell size
  Image color = test::make_color(w, h, [](float x, float y, int c) { return test::texture(x, y, c); });
  Image gb = test::make_gbuffer(w, h, [](int x, int, float& mx, float& my, float& d) {
    mx = x < 40 ? -2.0f : 3.0f;  // a discontinuity, and motion towards and away from the border
    my = 1.0f;
    d = x < 40 ? 3.0f : 5.0f;
  });
  for (int cell : {2, 4, 8, 16, 32}) {
    MorphOptions o;
    ASSERT_TRUE(apply_args(params(o), {"--grid", std::to_string(cell)}));
    o.debug_layers = true;
    Morpher m(o);
    std::vector<Image> out;
    ASSERT_TRUE(m.process(color, &gb, nullptr, out)) << "cell " << cell;
    for (const auto& img : out) {
      ASSERT_EQ(img.width(), w);
      for (const char* ch : {"R", "G", "B", "debug.blur"})
        for (std::size_t i = 0; i < img.pixel_count(); ++i) ASSERT_TRUE(std::isfinite(img.plane(ch)[i])) << ch;
    }
    // The in-between frames stay within the range of the input (bilinear samples and blur never overshoot).
    for (std::size_t i = 0; i < color.pixel_count(); ++i) {
      ASSERT_GE(out[1].plane("G")[i], 0.05f) << "cell " << cell;
      ASSERT_LE(out[1].plane("G")[i], 0.7f) << "cell " << cell;
    }
  }
}

TEST(MorphBaselines, RepeatBlendAndWarp) {
  const int w = 48, h = 32;
  Image a = test::make_color(w, h, [](float x, float y, int c) { return test::texture(x, y, c); });
  Image b = test::make_color(w, h, [](float x, float y, int c) { return test::texture(x - 3.0f, y, c); });
  Image gb = test::make_gbuffer(w, h, [](int, int, float& mx, float& my, float& d) { mx = -3.0f; my = 0.0f; d = 1.0f; });
  std::vector<Image> out;
  MorphOptions o;
  o.method = "repeat";
  ASSERT_TRUE(Morpher(o).process(a, nullptr, nullptr, out));
  EXPECT_EQ(out[2].plane("G")[100], a.plane("G")[100]);
  o.method = "blend";
  ASSERT_TRUE(Morpher(o).process(a, nullptr, &b, out));
  EXPECT_NEAR(out[1].plane("R")[77], (2.0f * a.plane("R")[77] + b.plane("R")[77]) / 3.0f, 1e-6f);
  EXPECT_NEAR(out[2].plane("R")[77], (a.plane("R")[77] + 2.0f * b.plane("R")[77]) / 3.0f, 1e-6f);
  o.method = "warp";
  ASSERT_TRUE(Morpher(o).process(a, &gb, nullptr, out));
  // Integer shifts: slot k moves every pixel k px right; the first k columns are holes (black).
  for (int k = 1; k < 3; ++k)
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const float v = out[std::size_t(k)].plane("B")[y * w + x];
        if (x < k) {
          ASSERT_EQ(v, 0.0f);
        } else {
          ASSERT_EQ(v, a.plane("B")[y * w + x - k]);
        }
      }
}

TEST(MorphBadInput, ClearErrors) {
  const int w = 32, h = 24;
  Image color = test::make_color(w, h, [](float x, float y, int c) { return test::texture(x, y, c); });
  Image no_motion(w, h);
  no_motion.add_channel("depth.Z", 1.0f);
  std::vector<Image> out;
  Morpher m{MorphOptions{}};
  Status s = m.process(color, &no_motion, nullptr, out);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().kind, ErrorKind::Input);
  EXPECT_NE(s.error().message.find("motion"), std::string::npos) << s.error().message;

  Image small = test::make_gbuffer(16, 16, [](int, int, float& mx, float& my, float& d) { mx = my = 0.0f; d = 1.0f; });
  s = m.process(color, &small, nullptr, out);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().kind, ErrorKind::Input);
  EXPECT_NE(s.error().message.find("16x16"), std::string::npos) << s.error().message;

  s = m.process(color, nullptr, nullptr, out);
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message.find("G-buffer"), std::string::npos);

  MorphOptions o;
  o.factor = 1;
  s = Morpher(o).process(color, &small, nullptr, out);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().kind, ErrorKind::Usage);
  EXPECT_NE(s.error().message.find("factor"), std::string::npos);

  o.factor = 3;
  ASSERT_TRUE(apply_args(params(o), {"--grid", "6"}));  // inside --grid's range; not a power of two
  s = Morpher(o).process(color, &small, nullptr, out);
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message.find("power of two"), std::string::npos);

  Image no_rgb(w, h);
  no_rgb.add_channel("R");
  s = Morpher(MorphOptions{}).process(no_rgb, &small, nullptr, out);
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message.find("'G'"), std::string::npos);
}

}  // namespace
}  // namespace temporal::morph
