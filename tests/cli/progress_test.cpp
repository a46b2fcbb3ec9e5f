// The progress line every tool draws on a terminal (apps/common/tool.h): no rate before there is time to measure
// one (issue 13: "16666666.7 frames/s" on frame 0), three significant digits, an estimate of the time left.
#include "tool.h"

#include <gtest/gtest.h>

#include <algorithm>

namespace temporal::tool {
namespace {

TEST(Progress, NoRateBeforeHalfASecond) {
  // The first frame done 60 ns after a clock read: the old line said 16666666.7 frames/s.
  EXPECT_EQ(progress_text("compare", 0, 1, 32, 6e-8), "compare: frame 0 (1/32)");
  EXPECT_EQ(progress_text("compare", 3, 4, 32, 0.49), "compare: frame 3 (4/32)");
}

TEST(Progress, RateAndTimeLeft) {
  // 10 of 40 frames in 2 s: 5 frames/s, 30 frames left -> 6 s.
  EXPECT_EQ(progress_text("filter-phlm", 9, 10, 40, 2.0), "filter-phlm: frame 9 (10/40, 5.00 frames/s, ETA 6.0 s)");
  // 3 of 1000 in 1.5 s: 2 frames/s, 997 left -> 498.5 s = 8 min 19 s (rounded to the second).
  EXPECT_EQ(progress_text("render-gbuffer", 2, 3, 1000, 1.5),
            "render-gbuffer: frame 2 (3/1000, 2.00 frames/s, ETA 8 min 19 s)");
  // Fast tools: three digits, never an exponent.
  EXPECT_EQ(progress_text("compare", 1233, 1234, 2000, 1.0), "compare: frame 1233 (1234/2000, 1234 frames/s, ETA 0.6 s)");
  EXPECT_EQ(progress_text("compare", 5, 6, 6, 0.8), "compare: frame 5 (6/6, 7.50 frames/s)");  // done: no ETA
  EXPECT_EQ(progress_text("upsample-st", 0, 1, 9, 40.0), "upsample-st: frame 0 (1/9, 0.0250 frames/s, ETA 5 min 20 s)");
}

TEST(Progress, Durations) {
  EXPECT_EQ(duration_text(0.44), "0.4 s");
  EXPECT_EQ(duration_text(12.4), "12 s");
  EXPECT_EQ(duration_text(185.0), "3 min 05 s");
  EXPECT_EQ(duration_text(3725.0), "1 h 02 min");
  EXPECT_EQ(duration_text(-1.0), "?");
}

}  // namespace
}  // namespace temporal::tool

namespace temporal::tool {
namespace {

// Off a terminal (a log file, a Snakemake or Slurm job log) progress is plain lines: one per interval once the run
// has taken that long, then the last frame; a run shorter than the interval prints nothing.
TEST(ProgressLines, OneLinePerIntervalAndTheLastOnly) {
  testing::internal::CaptureStderr();
  {
    Progress p("tool", 3, std::chrono::steady_clock::now(), Progress::Mode::Lines, 0.0);
    p.step(10);
    p.step(11);
    p.step(12);
  }
  const std::string every = testing::internal::GetCapturedStderr();
  EXPECT_EQ(every.find('\r'), std::string::npos) << every;
  EXPECT_NE(every.find("tool: frame 10 (1/3"), std::string::npos) << every;
  EXPECT_NE(every.find("tool: frame 12 (3/3"), std::string::npos) << every;
  EXPECT_EQ(std::count(every.begin(), every.end(), '\n'), 3) << every;

  testing::internal::CaptureStderr();
  {
    Progress p("tool", 3, std::chrono::steady_clock::now(), Progress::Mode::Lines, 3600.0);
    p.step(10);
    p.step(11);
    p.step(12);
  }
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
}

}  // namespace
}  // namespace temporal::tool
