#include "temporal/io/color_config.h"
#include "temporal/core/image.h"

#include "test_support.h"

#include <cmath>
#include <cstdlib>
#include <fstream>

namespace temporal {
namespace {

TEST(Color, YCgCoInlineMatchesHandValuesAndInverts) {
  float y, cg, co;
  rgb_to_ycgco(1.0f, 0.5f, 0.25f, y, cg, co);
  EXPECT_FLOAT_EQ(y, 0.25f + 0.25f + 0.0625f);
  EXPECT_FLOAT_EQ(cg, -0.25f + 0.25f - 0.0625f);
  EXPECT_FLOAT_EQ(co, 0.5f - 0.125f);
  float r, g, b;
  ycgco_to_rgb(y, cg, co, r, g, b);
  EXPECT_FLOAT_EQ(r, 1.0f);
  EXPECT_FLOAT_EQ(g, 0.5f);
  EXPECT_FLOAT_EQ(b, 0.25f);
  EXPECT_FLOAT_EQ(luminance(1, 1, 1), 1.0f);
}

Image ramp() {
  Image image(5, 4);
  float* r = image.add_channel("R");
  float* g = image.add_channel("G");
  float* b = image.add_channel("B");
  for (std::size_t i = 0; i < image.pixel_count(); ++i) {
    r[i] = float(i) / 20.0f;
    g[i] = 1.0f - float(i) / 25.0f;
    b[i] = 0.3f + 0.01f * float(i);
  }
  return image;
}

const std::vector<std::string> kRgb{"R", "G", "B"};

TEST(Color, BuiltinYCgCoAgreesWithInline) {
  const ColorConfig config = ColorConfig::builtin();
  Image image = ramp();
  const Image original = image;
  ASSERT_TRUE(config.convert(image, kRgb, colorspace::kSceneLinear, colorspace::kYCgCo));
  for (std::size_t i = 0; i < image.pixel_count(); ++i) {
    float y, cg, co;
    rgb_to_ycgco(original.plane("R")[i], original.plane("G")[i], original.plane("B")[i], y, cg, co);
    EXPECT_NEAR(image.plane("R")[i], y, 1e-6f);
    EXPECT_NEAR(image.plane("G")[i], cg, 1e-6f);
    EXPECT_NEAR(image.plane("B")[i], co, 1e-6f);
  }
  ASSERT_TRUE(config.convert(image, kRgb, colorspace::kYCgCo, colorspace::kSceneLinear));
  EXPECT_TRUE(test::images_near(image, original, kRgb, 1e-6f, "ycgco_roundtrip"));
}

TEST(Color, DisplayEncodings) {
  const ColorConfig config = ColorConfig::builtin();
  Image image(3, 1);
  for (const auto& c : kRgb) {
    float* p = image.add_channel(c);
    p[0] = 0.0f;
    p[1] = 0.5f;
    p[2] = 0.002f;
  }
  Image srgb = image;
  ASSERT_TRUE(config.convert(srgb, kRgb, colorspace::kSceneLinear, colorspace::kSrgb));
  // IEC 61966-2-1: 1.055 * 0.5^(1/2.4) - 0.055 = 0.735357; linear toe: 12.92 * 0.002.
  EXPECT_NEAR(srgb.plane("R")[1], 0.735357f, 1e-4f);
  EXPECT_NEAR(srgb.plane("G")[2], 12.92f * 0.002f, 1e-4f);
  Image gamma = image;
  ASSERT_TRUE(config.convert(gamma, kRgb, colorspace::kSceneLinear, colorspace::kGamma22));
  EXPECT_NEAR(gamma.plane("B")[1], std::pow(0.5f, 1.0f / 2.2f), 1e-4f);
  EXPECT_FLOAT_EQ(*config.display_gamma(colorspace::kGamma22), 2.2f);
  EXPECT_FALSE(config.display_gamma("no-such-space"));
  EXPECT_FALSE(config.convert(gamma, kRgb, "no-such-space", colorspace::kSrgb));
}

TEST(Color, LoadsAConfigFileAndReportsBadOnes) {
  const auto dir = test::scratch_dir("color_config");
  const std::string path = (dir / "config.ocio").string();
  std::ofstream(path) << ColorConfig::builtin().serialize();
  auto loaded = ColorConfig::load(path);
  ASSERT_TRUE(loaded) << loaded.error().message;
  EXPECT_EQ(loaded->source(), path);
  EXPECT_EQ(loaded->color_spaces().size(), 4u);
  Image image = ramp();
  ASSERT_TRUE(loaded->convert(image, kRgb, colorspace::kSceneLinear, colorspace::kYCgCo));

  const std::string bad = (dir / "bad.ocio").string();
  std::ofstream(bad) << "ocio_profile_version: 2\nthis is: [not, a, config\n";
  auto broken = ColorConfig::load(bad);
  ASSERT_FALSE(broken);
  EXPECT_EQ(broken.error().kind, ErrorKind::Input);

  // An empty path falls back to $OCIO, then to the built-in config.
  ::setenv("OCIO", path.c_str(), 1);
  EXPECT_EQ(ColorConfig::load("")->source(), path);
  ::unsetenv("OCIO");
  EXPECT_EQ(ColorConfig::load("")->source(), "built-in");
}

}  // namespace
}  // namespace temporal
