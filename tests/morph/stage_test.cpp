// morph-120hz's stage on the sequence runner (temporal/morph/morph_stage.h, temporal/io/runner.h): output
// numbering and timing, blend's next frame, --perceive's window past the selected frames, the NaN policy.
// Frames are constant images, so every expected value is computed by hand.
#include "temporal/io/color_config.h"
#include "temporal/io/exr.h"
#include "temporal/io/runner.h"
#include "temporal/morph/morph_stage.h"

#include "synthetic.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

// The tool's file and colour services (morph-120hz passes the same).
static const temporal::morph::MorphStageIO kMorphIO{&temporal::read_exr_rgb, &temporal::load_display_gamma};

namespace temporal::morph {
namespace {

class MorphStageRun : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::scratch_dir(std::string("morph_stage_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  // Colour frame n of the sequence `name`, every value `v`, 40 Hz.
  void write_color(const std::string& name, int n, float v, bool with_fps = true) {
    Image c = test::make_color(6, 4, [v](float, float, int) { return v; });
    if (with_fps) c.metadata().fps = 40.0;
    c.metadata().frame = n;
    c.metadata().world_to_camera = glm::mat4(1.0f);
    ASSERT_TRUE(write_exr(path(name + "." + std::to_string(1000 + n).substr(1) + ".exr"), c));
  }
  void write_gbuffer(int n) {
    Image g = test::make_gbuffer(6, 4, [](int, int, float& mx, float& my, float& d) {
      mx = my = 0.0f;
      d = 2.0f;
    });
    ASSERT_TRUE(write_exr(path("g." + std::to_string(1000 + n).substr(1) + ".exr"), g));
  }
  Expected<RunSummary> run(const MorphStageOptions& o, const std::string& input, const std::string& frames,
                           const std::string& gbuffer = {}) {
    auto stage = make_morph_stage(o, kMorphIO);
    if (!stage) return stage.error();
    SequenceOptions seq;
    seq.input = path(input + ".###.exr");
    seq.gbuffer = gbuffer.empty() ? std::string() : path(gbuffer + ".###.exr");
    seq.out = path("out/o.####.exr");
    seq.frames = frames;
    RunHooks hooks;
    hooks.warning = [this](const std::string& file, const std::string&) { warned_.push_back(file); };
    return run_sequence(seq, **stage, {"morph-120hz test", "test"}, hooks);
  }
  float value(int frame, const char* channel = "R") const {
    auto img = read_exr(path("out/o." + std::to_string(10000 + frame).substr(1) + ".exr"));
    return img ? img->plane(channel)[5] : -1.0f;
  }
  std::filesystem::path dir_;
  std::vector<std::string> warned_;
};

TEST_F(MorphStageRun, BlendSeesTheNextSelectedFrameAndTheLastOneRepeats) {
  write_color("c", 0, 0.2f);
  write_color("c", 1, 0.5f);
  write_color("c", 2, 0.8f);
  MorphStageOptions o;
  o.morph.method = "blend";
  auto r = run(o, "c", "0-1");
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(r->frames, 2u);
  EXPECT_EQ(r->outputs, 6u);
  // Frame 0: slot k = (1 - k/3) 0.2 + (k/3) 0.5.
  EXPECT_NEAR(value(0), 0.2f, 1e-6f);
  EXPECT_NEAR(value(1), 0.3f, 1e-6f);
  EXPECT_NEAR(value(2), 0.4f, 1e-6f);
  // Frame 1 is the last selected frame: frame 2 is on disk but not selected, so frame 1 is repeated.
  for (int f = 3; f < 6; ++f) EXPECT_NEAR(value(f), 0.5f, 1e-6f) << f;
  // Selecting frame 2 too: frame 1 blends towards 0.8.
  ASSERT_TRUE(run(o, "c", "0-2"));
  EXPECT_NEAR(value(4), 0.6f, 1e-6f);
  EXPECT_NEAR(value(5), 0.7f, 1e-6f);

  auto info = read_exr_info(path("out/o.0004.exr"));
  ASSERT_TRUE(info);
  const FrameMetadata& md = info->metadata;
  EXPECT_EQ(*md.frame, 4);
  EXPECT_DOUBLE_EQ(*md.fps, 120.0);
  EXPECT_NEAR(*md.time, 4.0 / 120.0, 1e-7);
  EXPECT_EQ(md.extra.at("method"), "blend");
  // One rendered frame of latency is factor = 3 output frames: slot k of frame n is shown 3 output frames late.
  EXPECT_EQ(md.extra.at("latencyFrames"), "3");
  EXPECT_EQ(md.extra.at("sourceFrame"), "1");
  EXPECT_EQ(md.extra.at("slot"), "1");
  EXPECT_FALSE(md.world_to_camera.has_value()) << "an extrapolated slot has no camera of its own";
  EXPECT_TRUE(md.timings_ms.count("morph"));
  auto slot0 = read_exr_info(path("out/o.0003.exr"));
  ASSERT_TRUE(slot0);
  EXPECT_TRUE(slot0->metadata.world_to_camera.has_value()) << "slot 0 is the rendered frame";
}

TEST_F(MorphStageRun, NonFiniteInputIsCountedReportedAndReplacedByZero) {
  Image c = test::make_color(6, 4, [](float, float, int) { return 0.25f; });
  c.metadata().fps = 40.0;
  c.plane("G")[5] = std::numeric_limits<float>::quiet_NaN();
  c.plane("B")[7] = std::numeric_limits<float>::infinity();
  ASSERT_TRUE(write_exr(path("c.000.exr"), c));
  MorphStageOptions o;
  o.morph.method = "repeat";
  auto r = run(o, "c", "");
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(r->non_finite_input, 2u);
  ASSERT_EQ(warned_.size(), 1u);
  EXPECT_EQ(warned_[0], path("c.000.exr"));
  for (int f = 0; f < 3; ++f) {
    EXPECT_EQ(value(f, "G"), 0.0f) << f;
    EXPECT_EQ(value(f, "R"), 0.25f) << f;
  }
}

TEST_F(MorphStageRun, PerceiveReadsItsWindowPastTheSelectedFramesWhileTheyExist) {
  for (int n = 0; n < 3; ++n) {
    write_color("c", n, 0.3f * float(n));
    write_gbuffer(n);
  }
  MorphStageOptions o;
  o.perceive = true;  // window 3, zero motion: the perceived image is the mean of the window
  ASSERT_TRUE(run(o, "c", "0-0", "g"));
  EXPECT_NEAR(value(0), (0.0f + 0.3f + 0.6f) / 3.0f, 1e-6f);
  auto info = read_exr_info(path("out/o.0000.exr"));
  ASSERT_TRUE(info);
  EXPECT_EQ(info->metadata.extra.at("perceivedWindow"), "3");
  // At the end of the sequence the window shrinks to the frames that exist.
  ASSERT_TRUE(run(o, "c", "1-2", "g"));
  EXPECT_NEAR(value(1), (0.3f + 0.6f) / 2.0f, 1e-6f);
  EXPECT_NEAR(value(2), 0.6f, 1e-6f);
}

// --perceive --lag-reference: the native stream's bump moves right 1 px per 120 Hz frame; a stream whose content
// is 2 frames late (found by the search against native frame t) and that declares temporal:latencyFrames = 3
// (added) lags by 2 + 3 = 5 frames = 41.667 ms at 120 Hz.
TEST_F(MorphStageRun, PerceiveWithALagReferenceReportsTheLagApartFromTheBlur) {
  const int w = 64, h = 4;
  auto bump_frame = [&](const std::string& file, float centre, const char* latency) {
    Image c = test::make_color(w, h, [=](float x, float, int) {
      const float d = (x - centre) / 3.0f;
      return 0.5f * std::exp(-0.5f * d * d);
    });
    c.metadata().fps = 120.0;
    if (latency) c.metadata().extra["latencyFrames"] = latency;
    ASSERT_TRUE(write_exr(path(file), c));
  };
  for (int t = 0; t <= 12; ++t) {
    const std::string n = std::to_string(1000 + t).substr(1);
    bump_frame("native." + n + ".exr", 20.5f + float(t), nullptr);
    bump_frame("late." + n + ".exr", 20.5f + float(t) - 2.0f, "3");
    Image g = test::make_gbuffer(w, h, [](int, int, float& mx, float& my, float& d) {
      mx = -1.0f;
      my = 0.0f;
      d = 2.0f;
    });
    ASSERT_TRUE(write_exr(path("mg." + n + ".exr"), g));
  }
  MorphStageOptions o;
  o.perceive = true;
  auto stage = make_morph_stage(o, kMorphIO);
  ASSERT_TRUE(stage);
  SequenceOptions seq;
  seq.input = path("native.###.exr");
  seq.gbuffer = path("mg.###.exr");
  seq.out = path("pn/p.####.exr");
  seq.frames = "0-10";
  ASSERT_TRUE(run_sequence(seq, **stage, {"morph-120hz test", "test"}, {}));
  o.lag_reference = path("pn/p.####.exr");
  ASSERT_TRUE(run(o, "late", "2-4", "mg"));
  auto img = read_exr(path("out/o.0003.exr"));
  ASSERT_TRUE(img);
  const auto& md = img->metadata();
  EXPECT_EQ(md.extra.at("lagContentFrames"), "2.00000");
  EXPECT_EQ(md.extra.at("lagFrames"), "5.00000");
  EXPECT_EQ(md.extra.at("lagMs"), "41.6667");  // 5 * 1000 / 120
  EXPECT_EQ(md.extra.at("lagReferenceFrame"), "3");
  // The aligned layer is the native perceived frame 3 (interior pixels; the border repeats its edge tap).
  auto native3 = read_exr(path("pn/p.0003.exr"));
  ASSERT_TRUE(native3);
  for (int x = 8; x < w - 8; ++x) EXPECT_NEAR(img->plane("aligned.G")[x], native3->plane("G")[x], 1e-5f) << x;
  // A frame past the native perceived frames that exist: a clear input error.
  auto r = run(o, "late", "11-11", "mg");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().kind, ErrorKind::Input);
  EXPECT_NE(r.error().message.find("run --perceive on the native sequence through frame 11"), std::string::npos)
      << r.error().message;
}

TEST_F(MorphStageRun, ClearErrors) {
  write_color("nofps", 0, 0.5f, false);
  MorphStageOptions o;
  o.morph.method = "repeat";
  auto r = run(o, "nofps", "");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().kind, ErrorKind::Input);
  EXPECT_EQ(r.error().file, path("nofps.000.exr"));
  EXPECT_NE(r.error().message.find("--fps"), std::string::npos) << r.error().message;
  o.fps = 30.0;  // --fps replaces the missing header value
  ASSERT_TRUE(run(o, "nofps", ""));
  auto info = read_exr_info(path("out/o.0002.exr"));
  ASSERT_TRUE(info);
  EXPECT_DOUBLE_EQ(*info->metadata.fps, 90.0);

  o.morph.method = "didyk";  // reads motion and depth: --gbuffer is required
  r = run(o, "nofps", "");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().kind, ErrorKind::Usage);
  EXPECT_NE(r.error().message.find("--gbuffer"), std::string::npos) << r.error().message;

  // --lag-reference without --perceive would do nothing: refused.
  MorphStageOptions lag;
  lag.lag_reference = "native.####.exr";
  auto refused = make_morph_stage(lag, kMorphIO);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().kind, ErrorKind::Usage);
  EXPECT_NE(refused.error().message.find("--perceive"), std::string::npos) << refused.error().message;

  // Several outputs per input frame need a placeholder in --out, even for a single input file.
  auto stage = make_morph_stage(MorphStageOptions{}, kMorphIO);
  ASSERT_TRUE(stage);
  SequenceOptions seq;
  seq.input = path("nofps.000.exr");
  seq.out = path("single.exr");
  auto single = run_sequence(seq, **stage, {"t", "t"});
  ASSERT_FALSE(single);
  EXPECT_EQ(single.error().kind, ErrorKind::Usage);
  EXPECT_NE(single.error().message.find("placeholder"), std::string::npos) << single.error().message;
}

}  // namespace
}  // namespace temporal::morph
