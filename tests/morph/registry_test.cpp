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
static const temporal::morph::MorphStageIO kMorphIO{&temporal::read_exr_rgb, &temporal::load_display_gamma};

namespace temporal::morph {
namespace {

// --device (temporal/core/method.h): the implementations a method's entry lists decide which devices it takes; any
// other device is a usage error that names the devices the method has (repeat has no GPU kernel: the issue lists none
// for it), and a name that is no device names the choices.
TEST(MorphRegistry, DeviceChecksNameTheMethodsDevices) {
  EXPECT_EQ(implementation_devices(*find_entry("blend")), (std::vector<std::string>{"cpu", "gpu"}));
  EXPECT_TRUE(check_method_device(*find_entry("blend"), "gpu"));
  EXPECT_TRUE(check_method_device(*find_entry("repeat"), "cpu"));
  const Status s = check_method_device(*find_entry("repeat"), "gpu");
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().kind, ErrorKind::Usage);
  EXPECT_EQ(s.error().message,
            "--method repeat has no gpu implementation (it runs on: cpu): pass --device cpu or another --method");
  const Status unknown = check_method_device(*find_entry("blend"), "tpu");
  ASSERT_FALSE(unknown);
  EXPECT_NE(unknown.error().message.find("cpu, gpu"), std::string::npos) << unknown.error().message;
  MorphOptions o;
  o.method = "repeat";
  o.device = "gpu";
  EXPECT_FALSE(check(o)) << "check() refuses a device the method has no implementation on";
  // The factories the entry lists: a CPU one cannot fail and needs no context; a GPU one needs the context.
  EXPECT_FALSE(find_implementation(*find_entry("blend"), kCpuDevice)->make.needs_gpu());
  EXPECT_TRUE(find_implementation(*find_entry("blend"), kGpuDevice)->make.needs_gpu());
  EXPECT_TRUE(find_implementation(*find_entry("blend"), kCpuDevice)->make(nullptr, MorphOptions{}));
}

TEST(MorphRegistry, ListsEveryMethodWithWhatItReadsAndItsLatency) {
  std::vector<std::string> names;
  const MorphOptions defaults;
  for (const MethodEntry* e : registry()) {
    names.push_back(e->info.name);
    EXPECT_FALSE(e->info.summary.empty()) << e->info.name;
    EXPECT_NE(find_implementation(*e, kCpuDevice), nullptr) << e->info.name << " has no CPU implementation";
    EXPECT_FALSE(e->info.has_state) << e->info.name << ": no morph method keeps a history";
    EXPECT_TRUE(e->info.latency_frames) << e->info.name << " must say its latency";
  }
  EXPECT_EQ(names, (std::vector<std::string>{"didyk", "repeat", "blend", "warp"}));  // didyk first: the default
  auto layers = [&](const char* name) {
    std::vector<std::string> l;
    for (const LayerNeed& n : find_entry(name)->layers(defaults)) l.push_back(n.layer);
    return l;
  };
  EXPECT_EQ(layers("didyk"), (std::vector<std::string>{"motion", "depth"}));
  EXPECT_EQ(layers("warp"), (std::vector<std::string>{"motion", "depth"}));
  EXPECT_TRUE(layers("repeat").empty());
  EXPECT_TRUE(layers("blend").empty());
  // Only blend looks one rendered frame ahead, and so adds one rendered frame of latency.
  for (const MethodEntry* e : registry()) {
    EXPECT_EQ(e->lookahead, e->info.name == "blend" ? 1 : 0) << e->info.name;
    EXPECT_EQ(e->info.latency_frames.value_or(-1), e->info.name == "blend" ? 1 : 0) << e->info.name;
  }
  EXPECT_EQ(defaults.method, "didyk");
  EXPECT_EQ(find_entry("bilinear"), nullptr);
}

TEST(MorphRegistry, UnknownMethodIsAUsageErrorListingTheNames) {
  MorphOptions o;
  o.method = "bilinear";
  const Status c = check(o);
  ASSERT_FALSE(c);
  EXPECT_EQ(c.error().kind, ErrorKind::Usage);
  EXPECT_NE(c.error().message.find("didyk, repeat, blend, warp"), std::string::npos) << c.error().message;
  EXPECT_EQ(c.error().message.find("did you mean"), std::string::npos) << "bilinear is no typo of a method";
  o.method = "didy";
  EXPECT_NE(check(o).error().message.find("(did you mean 'didyk'?)"), std::string::npos) << check(o).error().message;

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
  for (const MethodEntry* e : registry()) {
    const std::string& name = e->info.name;
    MorphOptions o;
    o.method = name;
    o.debug_layers = true;
    Morpher morpher(o);
    std::vector<Image> out;
    ASSERT_TRUE(morpher.process(color, &gb, &color, out)) << name;
    ASSERT_EQ(out.size(), 3u) << name;
    for (std::size_t k = 0; k < out.size(); ++k) {
      for (const char* ch : {"R", "G", "B"})
        for (std::size_t i = 0; i < color.pixel_count(); ++i)
          ASSERT_NEAR(out[k].plane(ch)[i], color.plane(ch)[i], 1e-6f) << name << " slot " << k << " " << ch << " pixel " << i;
      for (const char* ch : kMorphDebugLayers) EXPECT_TRUE(out[k].has_channel(ch)) << name << " " << ch;
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
  ASSERT_TRUE(apply_args(params, {"--no-snap"}));
  EXPECT_EQ(value("--no-snap"), "on");
  // Range checks come from the list: factor 1, a blur floor above 1 and a NaN gamma are usage errors.
  o.morph.factor = 1;
  EXPECT_FALSE(check_params(params));
  o.morph.factor = 3;
  EXPECT_TRUE(check_params(params));
  EXPECT_FALSE(apply_args(params, {"--min-blur", "1.5"}));
  EXPECT_FALSE(check_params(params));
  ASSERT_TRUE(apply_args(params, {"--min-blur", "0"}));
  EXPECT_TRUE(check_params(params));
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
  ASSERT_TRUE(apply_args(morph_stage_params(o), {"--grid", "6"}));
  auto s = make_morph_stage(o, kMorphIO);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().kind, ErrorKind::Usage);
  EXPECT_NE(s.error().message.find("power of two"), std::string::npos);
  ASSERT_TRUE(apply_args(morph_stage_params(o), {"--grid", "8"}));
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
}  // namespace temporal::morph
