// The pictures stage with hand-computed values: colour maps (matplotlib's published entries, FLIP's indexing, and
// NVIDIA's own FLIP map picture), display encoding through the OCIO config, heat maps and colour bars, G-buffer
// pictures, picture operations, crops, grids, temporal profiles, labels, files and the H.264 video.
#include "temporal/io/exr.h"
#include "temporal/core/image.h"
#include "temporal/metrics/flip.h"
#include "temporal/pictures/colormap.h"
#include "temporal/pictures/display.h"
#include "temporal/pictures/picture.h"
#include "temporal/pictures/profile.h"
#include "temporal/pictures/sheet.h"
#include "temporal/pictures/text.h"
#include "temporal/pictures/video.h"
#include "temporal/pictures/visualize.h"

#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>

namespace temporal {
namespace {

namespace fs = std::filesystem;

::testing::AssertionResult rgb_is(const Rgb8& got, int r, int g, int b) {
  if (got.r == r && got.g == g && got.b == b) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "(" << int(got.r) << ", " << int(got.g) << ", " << int(got.b) << ") instead of ("
                                       << r << ", " << g << ", " << b << ")";
}

// --- Colour maps -----------------------------------------------------------------------------------------------

TEST(Colormap, EntriesAreMatplotlibs) {
  // Values from matplotlib 3.6's _cm_listed.py (first, middle and last entries).
  const struct {
    Colormap map;
    int index;
    float r, g, b;
  } known[] = {
      {Colormap::Magma, 0, 0.001462f, 0.000466f, 0.013866f},   {Colormap::Magma, 128, 0.716387f, 0.214982f, 0.475290f},
      {Colormap::Magma, 255, 0.987053f, 0.991438f, 0.749504f}, {Colormap::Inferno, 0, 0.001462f, 0.000466f, 0.013866f},
      {Colormap::Inferno, 255, 0.988362f, 0.998364f, 0.644924f}, {Colormap::Viridis, 0, 0.267004f, 0.004874f, 0.329415f},
      {Colormap::Viridis, 255, 0.993248f, 0.906157f, 0.143936f}, {Colormap::Turbo, 0, 0.18995f, 0.07176f, 0.23217f},
      {Colormap::Turbo, 255, 0.47960f, 0.01583f, 0.01055f},
  };
  for (const auto& k : known) {
    const auto e = colormap_entry(k.map, k.index);
    EXPECT_FLOAT_EQ(e[0], k.r) << colormap_name(k.map) << " " << k.index;
    EXPECT_FLOAT_EQ(e[1], k.g) << colormap_name(k.map) << " " << k.index;
    EXPECT_FLOAT_EQ(e[2], k.b) << colormap_name(k.map) << " " << k.index;
  }
  EXPECT_FLOAT_EQ(colormap_entry(Colormap::Grey, 51)[0], 0.2f);
  EXPECT_FLOAT_EQ(colormap_entry(Colormap::Magma, -5)[0], 0.001462f);  // clamped
  EXPECT_FLOAT_EQ(colormap_entry(Colormap::Magma, 300)[2], 0.749504f);
}

TEST(Colormap, IndexingIsFlipsRoundedPosition) {
  EXPECT_EQ(colormap_index(0.0f, 0.0f, 1.0f), 0);
  EXPECT_EQ(colormap_index(0.5f, 0.0f, 1.0f), 128);     // round(127.5)
  EXPECT_EQ(colormap_index(0.498f, 0.0f, 1.0f), 127);   // round(126.99)
  EXPECT_EQ(colormap_index(1.0f, 0.0f, 1.0f), 255);
  EXPECT_EQ(colormap_index(-3.0f, 0.0f, 1.0f), 0);      // below the range
  EXPECT_EQ(colormap_index(7.0f, 0.0f, 1.0f), 255);     // above it
  EXPECT_EQ(colormap_index(0.05f, 0.0f, 0.2f), 64);     // round(63.75) within [0, 0.2]
  EXPECT_EQ(colormap_index(std::nanf(""), 0.0f, 1.0f), -1);
  // 8-bit colours: round(255 c) of the entry.
  EXPECT_TRUE(rgb_is(colormap_color(Colormap::Magma, 1.0f), 252, 253, 191));  // 251.70, 252.82, 191.12
  EXPECT_TRUE(rgb_is(colormap_color(Colormap::Magma, 0.0f), 0, 0, 4));        // 0.37, 0.12, 3.54
  EXPECT_TRUE(rgb_is(colormap_color(Colormap::Inferno, 0.5f, 0.0f, 1.0f),
                     int(std::lround(255 * colormap_entry(Colormap::Inferno, 128)[0])),
                     int(std::lround(255 * colormap_entry(Colormap::Inferno, 128)[1])),
                     int(std::lround(255 * colormap_entry(Colormap::Inferno, 128)[2]))));
  EXPECT_EQ(colormap_color(Colormap::Turbo, std::nanf("")), kNonFiniteColor);
  EXPECT_TRUE(parse_colormap("inferno"));
  EXPECT_EQ(parse_colormap("jet").error().kind, ErrorKind::Usage);
}

std::optional<fs::path> flip_reference_dir() {
  if (const char* env = std::getenv("TEMPORAL_FLIP_REFERENCE"); env && fs::is_directory(env)) return fs::path(env);
  const auto dir = test::source_dir() / ".." / "shared" / "flip-reference";
  if (fs::is_directory(dir)) return fs::canonical(dir);
  return std::nullopt;
}

std::vector<float> channel(const Picture& p, int c) {
  std::vector<float> v(std::size_t(p.width()) * std::size_t(p.height()));
  for (int y = 0; y < p.height(); ++y)
    for (int x = 0; x < p.width(); ++x) {
      const Rgb8& px = p.at(x, y);
      v[std::size_t(y) * std::size_t(p.width()) + std::size_t(x)] = float(c == 0 ? px.r : c == 1 ? px.g : px.b) / 255.0f;
    }
  return v;
}

// Our magma heat map of our FLIP map against the picture NVIDIA's FLIP tool wrote for the same pair: where the
// map value lies clearly inside an index (a quarter index from a rounding boundary) the colours must be identical,
// and everywhere no further apart than two neighbouring entries of the table (a value next to a boundary may
// round to the neighbouring entry: our FLIP differs from NVIDIA's in the last float bits).
TEST(Colormap, MagmaHeatMapOfFlipMatchesNvidiasPicture) {
  const auto dir = flip_reference_dir();
  if (!dir) GTEST_SKIP() << "../shared/flip-reference is absent (or set TEMPORAL_FLIP_REFERENCE)";
  auto ref = read_picture((*dir / "ldr_ref.png").string());
  auto test = read_picture((*dir / "ldr_phlm.png").string());
  auto nvidia = read_picture((*dir / "flipmap_ldr_phlm.png").string());
  ASSERT_TRUE(ref && test && nvidia);
  const int w = ref->width(), h = ref->height();
  const auto rr = channel(*ref, 0), rg = channel(*ref, 1), rb = channel(*ref, 2);
  const auto tr = channel(*test, 0), tg = channel(*test, 1), tb = channel(*test, 2);
  std::vector<float> map(std::size_t(w) * std::size_t(h));
  ASSERT_TRUE(evaluate_flip(FlipRange::Ldr, {tr.data(), tg.data(), tb.data()}, {rr.data(), rg.data(), rb.data()}, w, h, {},
                            map.data()));
  const Picture ours = heat_map(map.data(), nullptr, w, h, Colormap::Magma, 0.0f, 1.0f);
  std::size_t clear = 0, clear_equal = 0;
  int worst = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const Rgb8 a = ours.at(x, y), b = nvidia->at(x, y);
      const int d = std::max({std::abs(a.r - b.r), std::abs(a.g - b.g), std::abs(a.b - b.b)});
      worst = std::max(worst, d);
      // Index boundaries lie at 255 v = k + 0.5; a value a quarter index away from them rounds to one index
      // however the last float bits of the two implementations fall.
      const float at = 255.0f * map[std::size_t(y) * std::size_t(w) + std::size_t(x)] + 0.5f;
      const float frac = at - std::floor(at);
      if (frac > 0.25f && frac < 0.75f) {
        ++clear;
        clear_equal += d == 0;

      }
    }
  std::printf("magma FLIP map: %zu of %zu clear pixels identical to NVIDIA's picture, largest difference %d codes\n",
              clear_equal, clear, worst);
  int neighbours = 0;  // the largest code step between two neighbouring magma entries
  for (int i = 0; i < 255; ++i) {
    const Rgb8 a = colormap_color(Colormap::Magma, float(i) / 255.0f), b = colormap_color(Colormap::Magma, float(i + 1) / 255.0f);
    neighbours = std::max({neighbours, std::abs(a.r - b.r), std::abs(a.g - b.g), std::abs(a.b - b.b)});
  }
  EXPECT_GT(clear, std::size_t(w) * std::size_t(h) / 3);
  EXPECT_EQ(clear_equal, clear);
  EXPECT_LE(worst, neighbours);
}

// --- Display encoding ----------------------------------------------------------------------------------------

TEST(Display, SrgbThroughTheOcioConfig) {
  auto enc = DisplayEncoder::create({});
  ASSERT_TRUE(enc) << enc.error().message;
  // sRGB OETF: 1.055 * 0.18^(1/2.4) - 0.055 = 0.46135 -> code 117.6 -> 118; 0.0031308 * 12.92 -> 0.04045 -> 10.
  const float values[6] = {0.0f, 0.18f, 1.0f, 4.0f, 0.0031308f, -1.0f};
  const float nan = std::nanf("");
  const float grey[6] = {0.18f, nan, 0.18f, 0.18f, 0.18f, std::numeric_limits<float>::infinity()};
  const float* planes[3] = {values, values, grey};
  auto p = enc->encode(planes, 6, 1);
  ASSERT_TRUE(p);
  EXPECT_TRUE(rgb_is(p->at(0, 0), 0, 0, 118));
  EXPECT_TRUE(rgb_is(p->at(1, 0), kNonFiniteColor.r, kNonFiniteColor.g, kNonFiniteColor.b));  // a NaN channel
  EXPECT_TRUE(rgb_is(p->at(2, 0), 255, 255, 118));
  EXPECT_TRUE(rgb_is(p->at(3, 0), 255, 255, 118));  // above 1: clamped
  EXPECT_TRUE(rgb_is(p->at(4, 0), 10, 10, 118));
  EXPECT_EQ(p->at(5, 0), kNonFiniteColor);           // an Inf channel
  // One plane is grey; +1 stop doubles the values first.
  DisplayOptions o;
  o.exposure = 1.0;
  auto brighter = DisplayEncoder::create(o);
  ASSERT_TRUE(brighter);
  const float half[1] = {0.09f};
  const float* one[1] = {half};
  auto q = brighter->encode(one, 1, 1);
  ASSERT_TRUE(q);
  EXPECT_TRUE(rgb_is(q->at(0, 0), 118, 118, 118));
  // Gamma 2.2: 0.18^(1/2.2) = 0.45865 -> 117.0.
  o = {};
  o.display = colorspace::kGamma22;
  auto gamma = DisplayEncoder::create(o);
  ASSERT_TRUE(gamma);
  const float v18[1] = {0.18f};
  const float* g1[1] = {v18};
  EXPECT_TRUE(rgb_is(gamma->encode(g1, 1, 1)->at(0, 0), 117, 117, 117));
  o.display = "no_such_display";
  auto bad = DisplayEncoder::create(o);
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().kind, ErrorKind::Usage);
  EXPECT_NE(bad.error().message.find("srgb_display"), std::string::npos) << bad.error().message;
}

// The reference's scene-linear EXR through our sRGB display encoding gives the 8-bit PNG made from it for the FLIP
// reference (linear -> sRGB with OCIO, clamped; ../shared/flip-reference/README.md): within one code value
// (half-float input, rounding).
TEST(Display, MatchesTheFlipReferencesLdrPicture) {
  const auto dir = flip_reference_dir();
  if (!dir) GTEST_SKIP() << "../shared/flip-reference is absent (or set TEMPORAL_FLIP_REFERENCE)";
  auto exr = read_exr((*dir / "hdr_ref.exr").string());
  auto png = read_picture((*dir / "ldr_ref.png").string());
  ASSERT_TRUE(exr && png);
  auto enc = DisplayEncoder::create({});
  ASSERT_TRUE(enc);
  const std::vector<std::string> rgb = {"R", "G", "B"};
  auto ours = enc->encode(*exr, rgb);
  ASSERT_TRUE(ours);
  int worst = 0;
  for (int y = 0; y < png->height(); ++y)
    for (int x = 0; x < png->width(); ++x) {
      const Rgb8 a = ours->at(x, y), b = png->at(x, y);
      worst = std::max({worst, std::abs(a.r - b.r), std::abs(a.g - b.g), std::abs(a.b - b.b)});
    }
  EXPECT_LE(worst, 1);
}

// --- Heat maps, colour bars, G-buffer pictures ----------------------------------------------------------------

TEST(Visualize, HeatMapMarksInvalidAndNonFinitePixels) {
  const float v[4] = {0.0f, 0.5f, std::numeric_limits<float>::infinity(), 0.25f};
  const float invalid[4] = {0.0f, 0.0f, 0.0f, 1.0f};
  const Picture p = heat_map(v, invalid, 2, 2, Colormap::Magma, 0.0f, 1.0f);
  EXPECT_EQ(p.at(0, 0), colormap_color(Colormap::Magma, 0.0f));
  EXPECT_EQ(p.at(1, 0), colormap_color(Colormap::Magma, 0.5f));
  EXPECT_EQ(p.at(0, 1), kNonFiniteColor);
  EXPECT_EQ(p.at(1, 1), kInvalidColor);
}

TEST(Visualize, ColourBarRunsFromLowToHigh) {
  auto font = Font::find();
  ASSERT_TRUE(font) << font.error().message;
  auto bar = colour_bar(Colormap::Inferno, 0.0f, 0.2f, "|error|", 200, *font);
  ASSERT_TRUE(bar) << bar.error().message;
  EXPECT_EQ(bar->width(), 200);
  // The ramp's row: its first and last pixels are the map's ends; the ramp is inside the outline.
  const int y = 4 + 3;
  int first = -1, last = -1;
  for (int x = 0; x < bar->width(); ++x)
    if (bar->at(x, y) == colormap_color(Colormap::Inferno, 0.0f, 0.0f, 0.2f) && first < 0) first = x;
  for (int x = bar->width() - 1; x >= 0; --x)
    if (bar->at(x, y) == colormap_color(Colormap::Inferno, 0.2f, 0.0f, 0.2f)) {
      last = x;
      break;
    }
  ASSERT_GE(first, 0);
  ASSERT_GT(last, first + 150);
  // In between, pixel x shows the value at its place on the ramp.
  for (int x : {first + 1, (first + last) / 2, last - 3}) {
    const float t = float(x - first) / float(last - first);
    EXPECT_EQ(bar->at(x, y), colormap_color(Colormap::Inferno, 0.2f * t, 0.0f, 0.2f)) << x;
  }
  // Labels are drawn (dark pixels under the ramp).
  int dark = 0;
  for (int yy = y + 10; yy < bar->height(); ++yy)
    for (int x = 0; x < bar->width(); ++x) dark += bar->at(x, yy).r < 100;
  EXPECT_GT(dark, 20);
}

TEST(Visualize, NiceCeilingAndQuantile) {
  EXPECT_FLOAT_EQ(nice_ceiling(0.013f), 0.02f);
  EXPECT_FLOAT_EQ(nice_ceiling(0.2f), 0.2f);
  EXPECT_FLOAT_EQ(nice_ceiling(0.21f), 0.25f);
  EXPECT_FLOAT_EQ(nice_ceiling(3.0f), 5.0f);
  EXPECT_FLOAT_EQ(nice_ceiling(6.0f), 10.0f);
  EXPECT_EQ(nice_ceiling(0.0731f), 0.1f);  // exactly the float 0.1f: its label reads "0.1"
  EXPECT_FLOAT_EQ(nice_ceiling(0.0f), 1.0f);
  const float v[6] = {5, 1, std::nanf(""), 3, 2, 4};
  EXPECT_FLOAT_EQ(plane_quantile(v, 6, 0.0), 1.0f);
  EXPECT_FLOAT_EQ(plane_quantile(v, 6, 0.5), 3.0f);
  EXPECT_FLOAT_EQ(plane_quantile(v, 6, 1.0), 5.0f);
}

TEST(Visualize, GBufferPictures) {
  // Depth: the nearest pixel white, the farthest 0.15 (code 38), background (far clip) black.
  const float z[3] = {1.0f, 4.0f, 100.0f};
  const Picture d = depth_picture(z, 3, 1, 100.0f);
  EXPECT_TRUE(rgb_is(d.at(0, 0), 255, 255, 255));
  EXPECT_TRUE(rgb_is(d.at(1, 0), 38, 38, 38));
  EXPECT_TRUE(rgb_is(d.at(2, 0), 0, 0, 0));
  // Normals: (N + 1) / 2; (0, 0, 0) is background.
  const float nx[2] = {0.0f, 0.0f}, ny[2] = {0.0f, 0.0f}, nz[2] = {1.0f, 0.0f};
  const Picture n = normal_picture(nx, ny, nz, 2, 1);
  EXPECT_TRUE(rgb_is(n.at(0, 0), 128, 128, 255));
  EXPECT_TRUE(rgb_is(n.at(1, 0), 0, 0, 0));
  // Motion: right = hue 0 (red), up on screen (y negative) = hue 90 (128, 255, 0), none = white, half = pale.
  const float mx[4] = {4.0f, 0.0f, 0.0f, 2.0f}, my[4] = {0.0f, -4.0f, 0.0f, 0.0f};
  float scale = 0.0f;
  const Picture m = motion_picture(mx, my, 4, 1, 4.0f, &scale);
  EXPECT_FLOAT_EQ(scale, 4.0f);
  EXPECT_TRUE(rgb_is(m.at(0, 0), 255, 0, 0));
  EXPECT_TRUE(rgb_is(m.at(1, 0), 128, 255, 0));
  EXPECT_TRUE(rgb_is(m.at(2, 0), 255, 255, 255));
  EXPECT_TRUE(rgb_is(m.at(3, 0), 255, 128, 128));
  // Ids: background black, distinct ids distinct colours.
  const std::uint32_t id[4] = {0, 1, 2, 1};
  const Picture i = id_picture(id, 4, 1);
  EXPECT_TRUE(rgb_is(i.at(0, 0), 0, 0, 0));
  EXPECT_NE(i.at(1, 0), i.at(2, 0));
  EXPECT_EQ(i.at(1, 0), i.at(3, 0));
  EXPECT_TRUE(rgb_is(hsv_color(240.0f, 1.0f, 1.0f), 0, 0, 255));
  EXPECT_TRUE(rgb_is(hsv_color(0.0f, 0.0f, 0.5f), 128, 128, 128));
}

// --- Pictures, crops, grids, profiles --------------------------------------------------------------------------

TEST(Picture, ZoomCropResizePasteOutline) {
  Picture p(2, 2);
  p.at(0, 0) = {10, 20, 30};
  p.at(1, 0) = {50, 60, 70};
  p.at(0, 1) = {90, 100, 110};
  p.at(1, 1) = {130, 140, 150};
  const Picture z = p.zoomed(3);
  EXPECT_EQ(z.width(), 6);
  EXPECT_EQ(z.at(2, 2), p.at(0, 0));
  EXPECT_EQ(z.at(3, 2), p.at(1, 0));
  EXPECT_EQ(z.at(5, 5), p.at(1, 1));
  EXPECT_TRUE(rgb_is(p.resized(1, 1).at(0, 0), 70, 80, 90));  // the mean of the four
  EXPECT_EQ(p.crop({1, 0, 5, 5}).width(), 1);                // clipped
  EXPECT_EQ(p.crop({1, 0, 5, 5}).at(0, 1), p.at(1, 1));
  Picture canvas(4, 4, kBlack);
  canvas.paste(p, 3, 3);  // only (0, 0) lands
  EXPECT_EQ(canvas.at(3, 3), p.at(0, 0));
  canvas.outline({0, 0, 3, 3}, kWhite);
  EXPECT_EQ(canvas.at(0, 2), kWhite);
  EXPECT_EQ(canvas.at(1, 1), kBlack);  // inside stays
}

TEST(Sheet, PickedCropsFindTheLargestErrorAndDoNotOverlap) {
  const int w = 64, h = 48;
  std::vector<float> score(std::size_t(w) * std::size_t(h), 0.01f);
  for (int y = 20; y < 28; ++y)
    for (int x = 40; x < 48; ++x) score[std::size_t(y) * w + std::size_t(x)] = 1.0f;  // the hot spot
  for (int y = 2; y < 6; ++y)
    for (int x = 2; x < 6; ++x) score[std::size_t(y) * w + std::size_t(x)] = 0.5f;    // a smaller one
  score[5] = std::nanf("");
  const auto crops = pick_crops(score.data(), w, h, 2, 16, 16);
  ASSERT_EQ(crops.size(), 2u);
  const Rect& a = crops[0];
  EXPECT_TRUE(a.x <= 40 && a.x + a.width >= 48 && a.y <= 20 && a.y + a.height >= 28) << a.x << "," << a.y;
  const Rect& b = crops[1];
  EXPECT_TRUE(b.x <= 2 && b.x + b.width >= 6 && b.y <= 2 && b.y + b.height >= 6) << b.x << "," << b.y;
  EXPECT_FALSE(a.x < b.x + b.width && b.x < a.x + a.width && a.y < b.y + b.height && b.y < a.y + a.height);
  EXPECT_EQ(default_crop_side(320, 256), 43);
  EXPECT_EQ(default_crop_side(64, 40), 16);
  EXPECT_EQ(default_crop_side(12, 40), 12);
  EXPECT_TRUE(pick_crops(score.data(), w, h, 1, 100, 10).empty());
  auto r = parse_crop("10,20,30,40");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->x + r->y + r->width + r->height, 100);
  for (const char* bad : {"10,20,30", "1,2,3,0", "a,b,c,d", "1,2,3,4,5", "-1,2,3,4"}) EXPECT_FALSE(parse_crop(bad)) << bad;
}

TEST(Sheet, GridLayoutFitsFullHdAndIsEven) {
  GridLayout g = grid_layout(6, 320, 256, 20, 1920, 1080);
  EXPECT_EQ(g.columns, 3);
  EXPECT_EQ(g.rows, 2);
  EXPECT_EQ(g.width, 960);
  EXPECT_EQ(g.height, 552);
  g = grid_layout(2, 1920, 1080, 20, 1920, 1080);  // shrunk to fit, even
  EXPECT_EQ(g.columns, 2);
  EXPECT_LE(g.width, 1920);
  EXPECT_LE(g.height, 1080);
  EXPECT_EQ(g.width % 2, 0);
  EXPECT_EQ(g.height % 2, 0);
  EXPECT_EQ(g.tile_width, 960);
  g = grid_layout(1, 63, 41, 20, 1920, 1080);
  EXPECT_EQ(g.width, 64);
  EXPECT_EQ(g.height, 62);
}

TEST(Sheet, ComposeKeepsCellsWhereItsAreasSay) {
  auto font = Font::find();
  ASSERT_TRUE(font);
  SheetRow row;
  row.cells.push_back(SheetCell{Picture(20, 10, {255, 0, 0}), {"a"}, "a.exr", {}, {}});
  row.cells.emplace_back();
  row.cells.push_back(SheetCell{Picture(30, 10, {0, 0, 255}), {"b", "PSNR 30 dB"}, "b.exr", {}, Rgb8{0, 255, 0}});
  auto sheet = compose_sheet("title", {row}, *font);
  ASSERT_TRUE(sheet) << sheet.error().message;
  ASSERT_EQ(sheet->areas.size(), 2u);
  const auto& a = sheet->areas[0];
  const auto& b = sheet->areas[1];
  EXPECT_EQ(a.link, "a.exr");
  EXPECT_EQ(b.link, "b.exr");
  EXPECT_EQ(sheet->picture.at(a.rect.x + 5, a.rect.y + 5), (Rgb8{255, 0, 0}));
  EXPECT_EQ(sheet->picture.at(b.rect.x + 29, b.rect.y + 9), (Rgb8{0, 0, 255}));
  EXPECT_EQ(sheet->picture.at(b.rect.x - 1, b.rect.y), (Rgb8{0, 255, 0}));  // the frame
  EXPECT_GT(b.rect.x, a.rect.x + 20 + 8);                                 // the empty column keeps its place
}

TEST(Profile, RowAndColumnProfilesStackFramesOverTime) {
  // Frame f, pixel (x, y) = 100 f + 10 y + x on a 4x3 image.
  TemporalProfile row({ProfileAxis::Row, 1}, {"Y"});
  TemporalProfile column({ProfileAxis::Column, -1}, {"Y"});  // the middle column: x = 2
  for (int f = 0; f < 3; ++f) {
    std::vector<float> p(12);
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 4; ++x) p[std::size_t(y) * 4 + std::size_t(x)] = float(100 * f + 10 * y + x);
    const float* planes[1] = {p.data()};
    ASSERT_TRUE(row.add(planes, 4, 3));
    ASSERT_TRUE(column.add(planes, 4, 3));
  }
  const Image r = row.image();  // x to the right, time down
  ASSERT_EQ(r.width(), 4);
  ASSERT_EQ(r.height(), 3);
  EXPECT_FLOAT_EQ(r.plane("Y")[2 * 4 + 3], 213.0f);  // frame 2, row 1, x 3
  const Image c = column.image();  // time to the right, y down
  ASSERT_EQ(c.width(), 3);
  ASSERT_EQ(c.height(), 3);
  EXPECT_FLOAT_EQ(c.plane("Y")[1 * 3 + 2], 212.0f);  // y 1, frame 2, x 2
  TemporalProfile outside({ProfileAxis::Row, 3}, {"Y"});
  std::vector<float> p(12, 0.0f);
  const float* planes[1] = {p.data()};
  EXPECT_EQ(outside.add(planes, 4, 3).error().kind, ErrorKind::Usage);
  EXPECT_TRUE(parse_profile_line("row:12"));
  EXPECT_EQ(parse_profile_line("column:7")->index, 7);
  EXPECT_EQ(parse_profile_line("column")->axis, ProfileAxis::Column);
  for (const char* bad : {"diagonal", "row:", "row:-1", "row:x", "row=3"}) EXPECT_FALSE(parse_profile_line(bad)) << bad;
}

// --- Labels and files ------------------------------------------------------------------------------------------

TEST(Text, DrawsWithTheDejaVuFont) {
  auto font = Font::find();
  ASSERT_TRUE(font) << font.error().message;
  EXPECT_NE(font->path().find(".ttf"), std::string::npos);
  EXPECT_GT(font->text_width("PSNR 31.20 dB", 13), 40);
  EXPECT_GT(font->text_width("PSNR 31.20 dB", 26), font->text_width("PSNR 31.20 dB", 13));
  Picture p(120, 24);
  ASSERT_TRUE(font->draw(p, 2, 2, "frame 12", 14, kBlack));
  int dark = 0;
  for (int y = 0; y < p.height(); ++y)
    for (int x = 0; x < p.width(); ++x) dark += p.at(x, y).r < 128;
  EXPECT_GT(dark, 30);
  EXPECT_FALSE(Font::from_file("/nonexistent/font.ttf"));
}

TEST(Files, PngRoundTripJpegAndRefusedExtensions) {
  const auto dir = test::scratch_dir("pictures-files");
  Picture p(5, 3);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 5; ++x) p.at(x, y) = {std::uint8_t(40 * x), std::uint8_t(80 * y), 7};
  ASSERT_TRUE(write_picture(p, (dir / "a.png").string()));
  auto back = read_picture((dir / "a.png").string());
  ASSERT_TRUE(back);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 5; ++x) EXPECT_EQ(back->at(x, y), p.at(x, y));
  ASSERT_TRUE(write_picture(p, (dir / "sub" / "b.JPG").string()));  // folders made, any case
  EXPECT_TRUE(fs::exists(dir / "sub" / "b.JPG"));
  const auto tif = write_picture(p, (dir / "c.tif").string());
  ASSERT_FALSE(tif);
  EXPECT_EQ(tif.error().kind, ErrorKind::Usage);
  for (const auto& e : fs::directory_iterator(dir)) EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos);
}

// --- Video -----------------------------------------------------------------------------------------------------

TEST(Video, H264AtTheSequencesFrameRate) {
  if (find_ffmpeg().empty()) GTEST_FAIL() << "ffmpeg is not installed (setup.sh installs it)";
  const auto dir = test::scratch_dir("pictures-video");
  const std::string path = (dir / "v.mp4").string();
  VideoOptions o;
  o.fps = 120.0;
  auto v = VideoWriter::open(path, 64, 48, o);
  ASSERT_TRUE(v) << v.error().message;
  for (int f = 0; f < 12; ++f) {
    Picture p(64, 48, {std::uint8_t(20 * f), 100, 200});
    ASSERT_TRUE(v->add(p));
  }
  ASSERT_TRUE(v->finish());
  ASSERT_TRUE(fs::exists(path));
  std::string out;
  ASSERT_EQ(test::run_command("ffprobe -v error -select_streams v:0 -count_frames -show_entries "
                              "stream=codec_name,width,height,r_frame_rate,nb_read_frames,pix_fmt -of default=nw=1 " + path,
                              &out),
            0)
      << out;
  EXPECT_NE(out.find("codec_name=h264"), std::string::npos) << out;
  EXPECT_NE(out.find("width=64"), std::string::npos) << out;
  EXPECT_NE(out.find("r_frame_rate=120/1"), std::string::npos) << out;
  EXPECT_NE(out.find("nb_read_frames=12"), std::string::npos) << out;
  EXPECT_NE(out.find("pix_fmt=yuv420p"), std::string::npos) << out;
  // Odd sizes and a missing ffmpeg are refused with a message; nothing is left behind.
  EXPECT_EQ(VideoWriter::open((dir / "w.mp4").string(), 63, 48, o).error().kind, ErrorKind::Usage);
  o.ffmpeg = "/nonexistent/ffmpeg";
  auto missing = VideoWriter::open((dir / "w.mp4").string(), 64, 48, o);
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().message.find("apt-get install ffmpeg"), std::string::npos);
  for (const auto& e : fs::directory_iterator(dir)) EXPECT_EQ(e.path().filename().string(), "v.mp4");
}

}  // namespace
}  // namespace temporal
