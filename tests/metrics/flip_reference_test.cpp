// FLIP against NVIDIA's reference implementation (FLIP v1.6, C++ tool) run on this project's own images:
// ../shared/flip-reference/expected.json holds its mean FLIP for three test images against one reference, LDR
// (8-bit sRGB PNGs) and HDR (half-float EXRs, ACES, automatic exposures) at 67.0206 and 40 pixels per degree,
// and its error maps of the phlm frame as magma-coloured PNGs (README there). Skipped when the folder is absent.
#include "temporal/io/exr.h"
#include "temporal/core/image.h"
#include "temporal/metrics/flip.h"

#include "test_support.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>
#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>

namespace temporal {
namespace {

namespace fs = std::filesystem;

// ../shared/flip-reference beside the source tree; $TEMPORAL_FLIP_REFERENCE overrides it (a worktree whose
// parent has no `shared` folder).
std::optional<fs::path> reference_dir() {
  if (const char* env = std::getenv("TEMPORAL_FLIP_REFERENCE"); env && fs::is_directory(env)) return fs::path(env);
  const auto dir = test::source_dir() / ".." / "shared" / "flip-reference";
  if (fs::is_directory(dir)) return fs::canonical(dir);
  return std::nullopt;
}

constexpr const char* kAbsent = "../shared/flip-reference is absent (or set TEMPORAL_FLIP_REFERENCE to its folder)";

nlohmann::json expected(const fs::path& dir) {
  std::ifstream in(dir / "expected.json");
  return nlohmann::json::parse(in);
}

// An 8-bit RGB image as three planes of code / 255 (what NVIDIA's tool loads from a PNG).
struct Planes {
  int width = 0, height = 0;
  std::vector<float> r, g, b;
  FlipImage image() const { return {r.data(), g.data(), b.data()}; }
};

Planes read_png(const fs::path& path) {
  auto in = OIIO::ImageInput::open(path.string());
  EXPECT_TRUE(in) << path;
  Planes p;
  if (!in) return p;
  const auto& spec = in->spec();
  p.width = spec.width;
  p.height = spec.height;
  std::vector<unsigned char> pixels(std::size_t(spec.width) * std::size_t(spec.height) * std::size_t(spec.nchannels));
  EXPECT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT8, pixels.data()));
  const std::size_t n = std::size_t(p.width) * std::size_t(p.height);
  for (auto* v : {&p.r, &p.g, &p.b}) v->resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const unsigned char* px = pixels.data() + i * std::size_t(spec.nchannels);
    p.r[i] = float(px[0]) / 255.0f;
    p.g[i] = float(px[1]) / 255.0f;
    p.b[i] = float(px[2]) / 255.0f;
  }
  return p;
}

Planes read_rgb_exr(const fs::path& path) {
  auto img = read_exr(path.string());
  EXPECT_TRUE(img) << path;
  Planes p;
  if (!img) return p;
  p.width = img->width();
  p.height = img->height();
  const std::size_t n = img->pixel_count();
  p.r.assign(img->plane("R"), img->plane("R") + n);
  p.g.assign(img->plane("G"), img->plane("G") + n);
  p.b.assign(img->plane("B"), img->plane("B") + n);
  return p;
}

TEST(FlipReference, LdrMeansMatchNvidia) {
  const auto dir = reference_dir();
  if (!dir) GTEST_SKIP() << kAbsent;
  const auto j = expected(*dir);
  for (const auto& [name, e] : j["ldr"].items()) {
    const Planes ref = read_png(*dir / e["reference"].get<std::string>());
    const Planes test = read_png(*dir / name);
    ASSERT_EQ(ref.width, test.width);
    for (const auto& [key, ppd] : {std::pair<const char*, double>{"mean_ppd_default", kFlipDefaultPixelsPerDegree},
                                   std::pair<const char*, double>{"mean_ppd_40", 40.0}}) {
      FlipOptions o;
      o.pixels_per_degree = ppd;
      auto s = evaluate_flip(FlipRange::Ldr, test.image(), ref.image(), ref.width, ref.height, o);
      ASSERT_TRUE(s) << s.error().message;
      const double want = e[key].get<double>();
      EXPECT_NEAR(s->mean, want, 1e-4) << name << " " << key;
      std::printf("LDR %-14s %-17s ours %.6f  NVIDIA %.6f  diff %+.2e\n", name.c_str(), key, s->mean, want,
                  s->mean - want);
    }
  }
}

TEST(FlipReference, HdrMeansAndExposuresMatchNvidia) {
  const auto dir = reference_dir();
  if (!dir) GTEST_SKIP() << kAbsent;
  const auto j = expected(*dir);
  for (const auto& [name, e] : j["hdr"].items()) {
    const Planes ref = read_rgb_exr(*dir / e["reference"].get<std::string>());
    const Planes test = read_rgb_exr(*dir / name);
    ASSERT_EQ(ref.width, test.width);
    ASSERT_EQ(e["tone_mapper"], "ACES");
    for (const auto& [key, ppd] : {std::pair<const char*, double>{"mean_ppd_default", kFlipDefaultPixelsPerDegree},
                                   std::pair<const char*, double>{"mean_ppd_40", 40.0}}) {
      FlipOptions o;
      o.pixels_per_degree = ppd;
      FlipExposures x;
      auto s = evaluate_flip(FlipRange::Hdr, test.image(), ref.image(), ref.width, ref.height, o, nullptr, &x);
      ASSERT_TRUE(s) << s.error().message;
      const double want = e[key].get<double>();
      EXPECT_NEAR(s->mean, want, 1e-4) << name << " " << key;
      // expected.json gives the exposures with 4 decimals.
      EXPECT_NEAR(x.start, e["start_exposure"].get<double>(), 1e-4) << name;
      EXPECT_NEAR(x.stop, e["stop_exposure"].get<double>(), 1e-4) << name;
      EXPECT_EQ(x.count, e["num_exposures"].get<int>()) << name;
      std::printf("HDR %-14s %-17s ours %.6f  NVIDIA %.6f  diff %+.2e  exposures %.4f..%.4f x%d\n", name.c_str(), key,
                  s->mean, want, s->mean - want, x.start, x.stop, x.count);
    }
  }
}

// The reference tool colours its map with matplotlib's magma (256 entries), indexed by round(255 v), and
// writes 8-bit sRGB codes. OpenImageIO has the same map decimated to 17 knots (matplotlib's entries 0, 16,
// ..., 240, 255, stored as linear values) and interpolates them linearly in linear light, which is up to 5 codes
// off near black. Here the 17 knots are read back from ImageBufAlgo::color_map at t = k / 16, sRGB-encoded
// and interpolated with a Catmull-Rom spline at their entry numbers; over the reference maps this table
// differs from the reference tool's colours by at most (see the printed figures) a code value or two.
std::vector<std::array<int, 3>> magma_codes() {
  OIIO::ImageBuf ramp(OIIO::ImageSpec(17, 1, 1, OIIO::TypeDesc::FLOAT));
  for (int k = 0; k <= 16; ++k) {
    const float t = float(k) / 16.0f;
    ramp.setpixel(k, 0, &t, 1);
  }
  const OIIO::ImageBuf coloured = OIIO::ImageBufAlgo::color_map(ramp, 0, "magma");
  std::array<std::array<double, 3>, 17> knot{};
  for (int k = 0; k <= 16; ++k) {
    float rgb[3];
    coloured.getpixel(k, 0, rgb, 3);
    for (int c = 0; c < 3; ++c) {
      const double lin = std::clamp(double(rgb[c]), 0.0, 1.0);
      knot[std::size_t(k)][std::size_t(c)] = lin <= 0.0031308 ? 12.92 * lin : 1.055 * std::pow(lin, 1.0 / 2.4) - 0.055;
    }
  }
  auto at = [&](int k, int c) {  // knots extended linearly past both ends
    if (k < 0) return 2.0 * knot[0][std::size_t(c)] - knot[1][std::size_t(c)];
    if (k > 16) return 2.0 * knot[16][std::size_t(c)] - knot[15][std::size_t(c)];
    return knot[std::size_t(k)][std::size_t(c)];
  };
  std::vector<std::array<int, 3>> codes(256);
  for (int i = 0; i < 256; ++i) {
    const int k = std::min(i / 16, 15);
    const double span = k == 15 ? 15.0 : 16.0;  // the last knot is entry 255
    const double u = (double(i) - 16.0 * k) / span;
    for (int c = 0; c < 3; ++c) {
      const double p0 = at(k - 1, c), p1 = at(k, c), p2 = at(k + 1, c), p3 = at(k + 2, c);
      const double v = 0.5 * (2.0 * p1 + (p2 - p0) * u + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * u * u +
                              (3.0 * p1 - p0 - 3.0 * p2 + p3) * u * u * u);
      codes[std::size_t(i)][std::size_t(c)] = int(255.0 * std::clamp(v, 0.0, 1.0) + 0.5);
    }
  }
  return codes;
}

int code(float v) { return int(std::lround(v * 255.0f)); }

// Our map coloured as the reference tool colours its own (index round(255 v) into magma), against its PNG:
//  - with the magma table above: the largest per-channel code difference must stay within `tolerance`;
//  - with the reference tool's own colours: pixels whose value lies at least a quarter index from a rounding
//    boundary pick one index unambiguously; the reference PNG must show a single colour per such index (our
//    index = NVIDIA's at those pixels), and the largest difference over all pixels is printed.
void compare_map(const std::vector<float>& map, const Planes& png, const std::string& label, int tolerance) {
  const auto table = magma_codes();
  std::map<int, std::map<std::array<int, 3>, std::size_t>> seen;  // index -> reference colours at clear pixels
  int worst_table = 0;
  for (std::size_t i = 0; i < map.size(); ++i) {
    const float at = map[i] * 255.0f + 0.5f;
    const int index = int(at) % 256;
    const std::array<int, 3> got = {code(png.r[i]), code(png.g[i]), code(png.b[i])};
    for (int c = 0; c < 3; ++c)
      worst_table = std::max(worst_table, std::abs(table[std::size_t(index)][std::size_t(c)] - got[std::size_t(c)]));
    const float frac = at - std::floor(at);
    if (frac >= 0.25f && frac <= 0.75f) ++seen[index][got];
  }
  std::map<int, std::array<int, 3>> nvidia;  // the reference tool's colour of each index, where it shows
  std::size_t clear = 0, other = 0;
  for (const auto& [index, colours] : seen) {
    const auto top = std::max_element(colours.begin(), colours.end(),
                                      [](const auto& a, const auto& b) { return a.second < b.second; });
    nvidia[index] = top->first;
    for (const auto& [colour, count] : colours) (colour == top->first ? clear : other) += count;
  }
  int worst_nvidia = 0;
  for (std::size_t i = 0; i < map.size(); ++i) {
    const auto it = nvidia.find(int(map[i] * 255.0f + 0.5f) % 256);
    if (it == nvidia.end()) continue;
    const std::array<int, 3> got = {code(png.r[i]), code(png.g[i]), code(png.b[i])};
    for (int c = 0; c < 3; ++c) worst_nvidia = std::max(worst_nvidia, std::abs(it->second[std::size_t(c)] - got[std::size_t(c)]));
  }
  int table_error = 0;  // our magma table against the reference tool's colours
  for (const auto& [index, colour] : nvidia)
    for (int c = 0; c < 3; ++c)
      table_error = std::max(table_error, std::abs(table[std::size_t(index)][std::size_t(c)] - colour[std::size_t(c)]));
  std::printf("%s: max code-value difference %d with the OIIO magma table (which is itself within %d of the "
              "reference's colours), %d with the reference tool's own colours; %zu pixels away from an index "
              "boundary: %zu show another index's colour\n",
              label.c_str(), worst_table, table_error, worst_nvidia, clear + other, other);
  EXPECT_LE(worst_table, tolerance) << label;
  EXPECT_LE(worst_nvidia, tolerance) << label;
  EXPECT_GT(clear, map.size() / 2) << label;
  EXPECT_LE(other, (clear + other) / 1000) << label << ": indices disagree";
}

TEST(FlipReference, LdrErrorMapMatchesNvidia) {
  const auto dir = reference_dir();
  if (!dir) GTEST_SKIP() << kAbsent;
  const Planes ref = read_png(*dir / "ldr_ref.png");
  const Planes test = read_png(*dir / "ldr_phlm.png");
  std::vector<float> map(ref.r.size());
  ASSERT_TRUE(evaluate_flip(FlipRange::Ldr, test.image(), ref.image(), ref.width, ref.height, {}, map.data()));
  compare_map(map, read_png(*dir / "flipmap_ldr_phlm.png"), "LDR map", 4);
}

TEST(FlipReference, HdrErrorMapMatchesNvidia) {
  const auto dir = reference_dir();
  if (!dir) GTEST_SKIP() << kAbsent;
  const Planes ref = read_rgb_exr(*dir / "hdr_ref.exr");
  const Planes test = read_rgb_exr(*dir / "hdr_phlm.exr");
  std::vector<float> map(ref.r.size());
  ASSERT_TRUE(evaluate_flip(FlipRange::Hdr, test.image(), ref.image(), ref.width, ref.height, {}, map.data()));
  compare_map(map, read_png(*dir / "flipmap_hdr_phlm.png"), "HDR map", 4);
}

}  // namespace
}  // namespace temporal
