// Latency-aware scoring of morph-120hz's methods (docs/conventions.md, "Latency"; compare --latency-aware):
// blend needs rendered frame n+1 before it can show slot 1 of frame n, so its output frame t is displayed
// factor = 3 output frames late and must be judged against the native 120 Hz frame t + 3. A synthetic edge
// moving one pixel per 120 Hz frame gives every value by hand.
#include "temporal/io/exr.h"
#include "temporal/compare/comparison.h"
#include "temporal/io/color_config.h"
#include "temporal/io/exr.h"
#include "temporal/morph/morph_stage.h"
#include "temporal/io/runner.h"

#include "synthetic.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

// The tool's file and colour services (morph-120hz passes the same).
static const temporal::morph::MorphStageIO kMorphIO{&temporal::read_exr_rgb, &temporal::load_display_gamma};

namespace temporal::morph {
namespace {

constexpr int kW = 32, kH = 12;

class LatencyScoring : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::scratch_dir(std::string("morph_latency_") +
                             ::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  std::string path(const std::string& rel) const { return (dir_ / rel).string(); }
  static std::string num(int n) { return std::to_string(10000 + n).substr(1); }
  // A white-left edge: 1 for pixel columns x < edge, else 0 (R = G = B).
  void write_edge(const std::string& file, int edge, double fps) {
    Image c = test::make_color(kW, kH, [edge](float x, float, int) { return x < float(edge) ? 1.0f : 0.0f; });
    c.metadata().fps = fps;
    ASSERT_TRUE(write_exr(file, c));
  }
  // 40 Hz frames n = 0..3 with the edge at 8 + 3n, morphed to 120 Hz by `method`; the native 120 Hz frames
  // t = 0..last_native with the edge at 8 + t (the same motion: one pixel per 120 Hz frame).
  void make(const std::string& method, int last_native) {
    for (int n = 0; n <= 3; ++n) write_edge(path("in/c." + num(n) + ".exr"), 8 + 3 * n, 40.0);
    for (int t = 0; t <= last_native; ++t) write_edge(path("native/c." + num(t) + ".exr"), 8 + t, 120.0);
    MorphStageOptions o;
    o.morph.method = method;
    auto stage = make_morph_stage(o, kMorphIO);
    ASSERT_TRUE(stage) << stage.error().message;
    SequenceOptions seq;
    seq.input = path("in/c.####.exr");
    seq.out = path(method + "/c.####.exr");
    seq.frames = "0-3";
    auto r = run_sequence(seq, **stage, {"morph-120hz test", "test"}, {});
    ASSERT_TRUE(r) << r.error().message;
  }
  Expected<ComparisonReport> compare(const std::vector<std::string>& methods, const std::string& frames,
                                     std::vector<std::string>* warnings = nullptr) {
    ComparisonSetup s;
    s.reference = path("native/c.####.exr");
    for (const auto& m : methods) s.tests.push_back(path(m + "/c.####.exr"));
    s.frames = *FrameRange::parse(frames);
    s.latency_aware = true;
    ComparisonHooks hooks;
    hooks.warning = [warnings](const std::string&, const std::string& text) {
      if (warnings) warnings->push_back(text);
    };
    return compare_sequences(s, hooks);
  }
  std::filesystem::path dir_;
};

const FrameMetrics& row(const SequenceReport& s, int frame) {
  for (const auto& f : s.frames)
    if (f.frame == frame) return f;
  throw std::runtime_error("no frame " + std::to_string(frame));
}

TEST_F(LatencyScoring, BlendIsJudgedAgainstTheNativeFrameShownOneRenderedFrameLater) {
  make("blend", 14);
  make("repeat", 14);
  auto report = compare({"blend", "repeat"}, "3-8");
  ASSERT_TRUE(report) << report.error().message;
  const auto& blend = report->sequences[0];
  const auto& repeat = report->sequences[1];
  // Output frame t = 3n + k of blend is (1 - k/3) F_n + (k/3) F_{n+1}: the edge at 8 + 3n, a step of height
  // 1 - k/3 over the three columns 8 + 3n .. 10 + 3n, then 0. MSE over a row of 32 pixels (every channel alike):
  //  k = 0: latency-free against native t (edge 8 + 3n): identical, +inf.
  //         shown at t + 3 (edge 11 + 3n): three columns differ by 1: MSE 3/32.
  //  k = 1: latency-free, native edge 9 + 3n: (2/3)^2 + 2 (1/3)^2 = 2/3 per row: MSE 1/48.
  //         at t + 3, native edge 12 + 3n: 3 (2/3)^2 + 1 = 7/3 per row: MSE 7/96.
  //  k = 2: latency-free, native edge 10 + 3n: 2 (1/3)^2 + (2/3)^2 = 2/3: MSE 1/48.
  //         at t + 3, native edge 13 + 3n: 3 (1/3)^2 + 2 = 7/3: MSE 7/96.
  const double k0_shown = 10.0 * std::log10(32.0 / 3.0);  // 10.280 dB
  const double k12_free = 10.0 * std::log10(48.0);        // 16.812 dB
  const double k12_shown = 10.0 * std::log10(96.0 / 7.0);  // 11.372 dB
  for (int t = 3; t <= 8; ++t) {
    const auto& f = row(blend, t);
    const int k = t % 3;
    EXPECT_EQ(f.value("psnr_latency", 1), 3.0) << "latency_frames column, frame " << t;
    if (k == 0) {
      EXPECT_TRUE(std::isinf(f.value("psnr_rgb"))) << t;
      EXPECT_NEAR(f.value("psnr_latency"), k0_shown, 1e-3) << t;
    } else {
      EXPECT_NEAR(f.value("psnr_rgb"), k12_free, 1e-3) << t;
      EXPECT_NEAR(f.value("psnr_latency"), k12_shown, 1e-3) << t;
    }
    // repeat has no latency: both scores are the same comparison with native frame t. Slot k shows the edge k
    // columns behind: MSE k/32.
    const auto& g = row(repeat, t);
    EXPECT_EQ(g.value("psnr_latency", 1), 0.0);
    if (k == 0) EXPECT_TRUE(std::isinf(g.value("psnr_latency"))) << t;
    else EXPECT_NEAR(g.value("psnr_latency"), 10.0 * std::log10(32.0 / k), 1e-3) << t;
    EXPECT_EQ(g.value("psnr_latency"), g.value("psnr_rgb")) << t;
  }
  const auto s = summarize(blend, "psnr_latency");
  EXPECT_EQ(s.count, 6u);
  EXPECT_NEAR(s.mean, (2 * k0_shown + 4 * k12_shown) / 6.0, 1e-3);
  // Judged at the instant it is shown, blend's in-between slots (11.37 dB) fall behind repeat's (15.05 dB at
  // k = 1, 12.04 dB at k = 2), while the latency-free score puts blend ahead (16.81 dB).
  EXPECT_LT(row(blend, 4).value("psnr_latency"), row(repeat, 4).value("psnr_latency"));
}

TEST_F(LatencyScoring, FramesWhoseShownReferenceIsMissingHaveNoValueAndAreReported) {
  make("blend", 11);  // native frames 0..11: output frames 9..11 are shown at 12..14, not rendered
  std::vector<std::string> warnings;
  auto report = compare({"blend"}, "3-11", &warnings);
  ASSERT_TRUE(report) << report.error().message;
  const auto s = summarize(report->sequences[0], "psnr_latency");
  EXPECT_EQ(s.count, 6u);
  for (int t = 9; t <= 11; ++t) EXPECT_TRUE(std::isnan(row(report->sequences[0], t).value("psnr_latency"))) << t;
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("3 compared frames have no reference frame 3 frames later"), std::string::npos) << warnings[0];
  // The latency-free score is there for every frame.
  EXPECT_EQ(summarize(report->sequences[0], "psnr_rgb").count, 9u);
}

TEST_F(LatencyScoring, WithoutTheOptionNothingChanges) {
  make("blend", 14);
  ComparisonSetup s;
  s.reference = path("native/c.####.exr");
  s.tests = {path("blend/c.####.exr")};
  s.frames = *FrameRange::parse("3-8");
  auto report = compare_sequences(s);
  ASSERT_TRUE(report) << report.error().message;
  EXPECT_EQ(std::count(report->metrics.begin(), report->metrics.end(), "psnr_latency"), 0);
}

}  // namespace
}  // namespace temporal::morph
