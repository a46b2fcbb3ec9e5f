// The method registry of morph-120hz (temporal/morph/methods.h) and the parameters bound from it
// (temporal/morph/morph_stage.h).
#include "temporal/morph/methods.h"
#include "temporal/io/color_config.h"
#include "temporal/io/exr.h"
#include "temporal/morph/morph_stage.h"

#include "synthetic.h"

#include <gtest/gtest.h>

#include <set>

// The tool's file and colour services (morph-120hz passes the same).
static const temporal::MorphStageIO kMorphIO{&temporal::read_exr_rgb, &temporal::load_display_gamma};

namespace temporal {
namespace {

TEST(MorphRegistry, ListsEveryMethodWithWhatItReadsAndItsLatency) {
  std::vector<std::string> names;
  for (const auto& m : morph_methods()) {
    names.push_back(m.name);
    EXPECT_FALSE(m.summary.empty()) << m.name;
    EXPECT_NE(m.make, nullptr) << m.name;
  }
  EXPECT_EQ(names, (std::vector<std::string>{"didyk", "repeat", "blend", "warp"}));  // didyk first: the default
  auto entry = [](const char* name) { return *find_morph_method(name); };
  EXPECT_EQ(entry("didyk")->gbuffer_layers, (std::vector<std::string>{"motion", "depth"}));
  EXPECT_EQ(entry("warp")->gbuffer_layers, (std::vector<std::string>{"motion", "depth"}));
  EXPECT_TRUE(entry("repeat")->gbuffer_layers.empty());
  EXPECT_TRUE(entry("blend")->gbuffer_layers.empty());
  // Only blend looks one rendered frame ahead, and so adds one rendered frame of latency.
  for (const auto& m : morph_methods()) {
    EXPECT_EQ(m.lookahead, m.name == "blend" ? 1 : 0) << m.name;
    EXPECT_EQ(m.latency_frames, m.name == "blend" ? 1 : 0) << m.name;
  }
  EXPECT_EQ(MorphOptions{}.method, "didyk");
}

TEST(MorphRegistry, UnknownMethodIsAUsageErrorListingTheNames) {
  auto m = find_morph_method("bilinear");
  ASSERT_FALSE(m);
  EXPECT_EQ(m.error().kind, ErrorKind::Usage);
  EXPECT_NE(m.error().message.find("didyk, repeat, blend, warp"), std::string::npos) << m.error().message;
  MorphOptions o;
  o.method = "bilinear";
  std::vector<Image> out;
  Image color = test::make_color(8, 8, [](float, float, int) { return 0.5f; });
  Status s = Morpher(o).process(color, nullptr, nullptr, out);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().kind, ErrorKind::Usage);
}

// A static frame (zero motion, one depth) has nothing to extrapolate: every method must show it unchanged in
// every slot, up to float rounding (didyk's texture coordinates are barycentric sums, blend's (1 - a) v + a v):
// 1e-6 on values in [0.1, 0.6] is a few ulps, while a half-pixel shift of the texture would cost ~0.05.
TEST(MorphRegistry, EveryMethodReproducesAStaticFrameExactly) {
  const int w = 40, h = 24;
  Image color = test::make_color(w, h, [](float x, float y, int c) { return test::texture(x, y, c); });
  Image gb = test::make_gbuffer(w, h, [](int, int, float& mx, float& my, float& d) {
    mx = my = 0.0f;
    d = 3.0f;
  });
  for (const auto& m : morph_methods()) {
    MorphOptions o;
    o.method = m.name;
    o.debug_layers = true;
    Morpher morpher(o);
    std::vector<Image> out;
    ASSERT_TRUE(morpher.process(color, &gb, &color, out)) << m.name;
    ASSERT_EQ(out.size(), 3u) << m.name;
    for (std::size_t k = 0; k < out.size(); ++k) {
      for (const char* ch : {"R", "G", "B"})
        for (std::size_t i = 0; i < color.pixel_count(); ++i)
          ASSERT_NEAR(out[k].plane(ch)[i], color.plane(ch)[i], 1e-6f) << m.name << " slot " << k << " " << ch << " pixel " << i;
      for (const char* ch : kMorphDebugLayers) EXPECT_TRUE(out[k].has_channel(ch)) << m.name << " " << ch;
    }
  }
}

TEST(MorphStageParams, EveryFlagOnceBoundToTheLibraryDefaults) {
  MorphStageOptions o;
  const ParamList params = morph_stage_params(o);
  std::set<std::string> flags;
  for (const auto& p : params) EXPECT_TRUE(flags.insert(p.flag).second) << p.flag << " bound twice";
  for (const char* f : {"--method", "--factor", "--fps", "--debug-layers", "--perceive", "--window", "--gamma",
                        "--display", "--ocio", "--grid", "--snap-threshold", "--no-snap", "--blur-level",
                        "--distortion-low", "--distortion-high", "--min-blur", "--no-compensation", "--ppd",
                        "--screen-width-m", "--distance-m", "--pixels-x", "--no-tracking-limit"})
    EXPECT_TRUE(flags.count(f)) << f;
  auto value = [&](const std::string& flag) {
    for (const auto& p : params)
      if (p.flag == flag) return param_value_text(p);
    return std::string("(missing)");
  };
  // The defaults printed are the fields' own (one place): seed 004's 8x8 grid, N = 3, gamma 2.2.
  EXPECT_EQ(value("--method"), "didyk");
  EXPECT_EQ(value("--factor"), "3");
  EXPECT_EQ(value("--grid"), "8");
  EXPECT_EQ(value("--gamma"), "2.2");
  EXPECT_EQ(value("--window"), "3");
  // Inverted flags read "off" while the feature they turn off is on.
  EXPECT_EQ(value("--no-snap"), "off");
  o.morph.grid.snap = false;
  EXPECT_EQ(value("--no-snap"), "on");
  // Range checks come from the list: factor 1, a blur floor above 1 and a NaN gamma are usage errors.
  o.morph.factor = 1;
  EXPECT_FALSE(check_params(params));
  o.morph.factor = 3;
  EXPECT_TRUE(check_params(params));
  o.morph.min_blur = 1.5f;
  EXPECT_FALSE(check_params(params));
  o.morph.min_blur = 0.0f;
  o.morph.gamma = std::numeric_limits<float>::quiet_NaN();
  const Status s = check_params(params);
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message.find("--gamma"), std::string::npos) << s.error().message;
}

TEST(MorphStageParams, EyeTrackingPixelsPerDegree) {
  ViewingOptions v;
  // The paper's display: 1680 px across 2 atan(0.473 / (2 * 0.6)) = 43.0254 degrees: 39.0467 px/degree.
  EXPECT_NEAR(tracking_pixels_per_degree(v, 256), 39.0467f, 1e-3f);
  v.pixels_x = 0;  // the image fills the screen width: 840 px across the same 43.0254 degrees
  EXPECT_NEAR(tracking_pixels_per_degree(v, 840), 19.5233f, 1e-3f);
  v.ppd = 50.0f;
  EXPECT_EQ(tracking_pixels_per_degree(v, 840), 50.0f);
  v.tracking_limit = false;
  EXPECT_EQ(tracking_pixels_per_degree(v, 840), 0.0f);
}

TEST(MorphStage, InvalidOptionsAreRefusedBeforeAnyFrameIsRead) {
  MorphStageOptions o;
  o.morph.method = "nope";
  EXPECT_FALSE(make_morph_stage(o, kMorphIO));
  o.morph.method = "didyk";
  o.morph.grid.cell = 6;
  auto s = make_morph_stage(o, kMorphIO);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().kind, ErrorKind::Usage);
  EXPECT_NE(s.error().message.find("power of two"), std::string::npos);
  o.morph.grid.cell = 8;
  o.display = "no_such_display";
  EXPECT_FALSE(make_morph_stage(o, kMorphIO));
  o.display.clear();
  auto ok = make_morph_stage(o, kMorphIO);
  ASSERT_TRUE(ok);
  EXPECT_EQ((*ok)->inputs().outputs_per_frame, 3);
  EXPECT_TRUE((*ok)->inputs().gbuffer_required);
  o.morph.method = "blend";
  ok = make_morph_stage(o, kMorphIO);
  ASSERT_TRUE(ok);
  EXPECT_FALSE((*ok)->inputs().gbuffer_required);
  EXPECT_EQ((*ok)->inputs().lookahead, 1);
  EXPECT_FALSE((*ok)->inputs().lookahead_past_range);
  o.perceive = true;
  o.hold.window = 4;
  ok = make_morph_stage(o, kMorphIO);
  ASSERT_TRUE(ok);
  EXPECT_EQ((*ok)->inputs().lookahead, 3);
  EXPECT_TRUE((*ok)->inputs().lookahead_past_range);
}

}  // namespace
}  // namespace temporal
