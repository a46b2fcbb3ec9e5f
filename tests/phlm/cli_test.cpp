// filter-phlm's command line: every method on a tiny synthetic sequence, --state-out / --state-in resume,
// errors and exit codes.
#include "temporal/io/exr.h"
#include "temporal/phlm/filters.h"

#include "test_support.h"

#include <gtest/gtest.h>

#include <utility>

#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <random>

namespace {

using namespace temporal;
using namespace temporal::phlm;
namespace fs = std::filesystem;

// Writes frames 0..n-1 of a noisy 12x10 colour sequence with a G-buffer (motion 0.5 px right).
void write_sequence(const fs::path& dir, int n) {
  std::mt19937 rng(42);
  std::normal_distribution<float> noise(0.0f, 0.1f);
  for (int t = 0; t < n; ++t) {
    Image color(12, 10), g(12, 10);
    for (const char* c : {"R", "G", "B"}) {
      float* p = color.add_channel(c);
      for (std::size_t i = 0; i < color.pixel_count(); ++i) p[i] = 0.4f + 0.02f * float(i % 12) + noise(rng);
    }
    g.add_channel("motion.X", -0.5f);
    g.add_channel("motion.Y", 0.0f);
    g.add_channel("depth.Z", 3.0f);
    g.add_uint_channel("id", 1);
    color.metadata().frame = t;
    color.metadata().jitter = glm::vec2(0.25f, -0.25f);
    if (t == 0) color.metadata().camera_cut = true;
    char name[64];
    std::snprintf(name, sizeof name, "color.%04d.exr", t);
    ASSERT_TRUE(write_exr((dir / name).string(), color));
    std::snprintf(name, sizeof name, "gbuffer.%04d.exr", t);
    ASSERT_TRUE(write_exr((dir / name).string(), g));
  }
}

std::string tool() { return test::tool_path("filter-phlm").string(); }

TEST(FilterPhlmCli, HelpReportsStateBytesAndDefaults) {
  std::string out;
  ASSERT_EQ(test::run_command(tool() + " --help", &out), 0);
  EXPECT_NE(out.find("104 bytes"), std::string::npos) << out;
  EXPECT_NE(out.find("28 bytes"), std::string::npos);
  EXPECT_NE(out.find("0.998"), std::string::npos);
  EXPECT_NE(out.find("--state-out"), std::string::npos);
}

TEST(FilterPhlmCli, EveryMethodWritesTheSequence) {
  const auto dir = test::scratch_dir("filter-phlm-cli-methods");
  write_sequence(dir, 4);
  for (const std::string m : {"phlm", "taa", "ema", "fxaa"}) {
    std::string out;
    const std::string cmd = tool() + " --input " + (dir / "color.####.exr").string() + " --gbuffer " +
                            (dir / "gbuffer.####.exr").string() + " --out " + (dir / (m + ".####.exr")).string() +
                            " --method " + m + " --debug-layers";
    ASSERT_EQ(test::run_command(cmd, &out), 0) << cmd << "\n" << out;
    auto img = read_exr((dir / (m + ".0003.exr")).string());
    ASSERT_TRUE(img) << img.error().message;
    EXPECT_TRUE(img->plane("R"));
    EXPECT_EQ(img->metadata().frame.value_or(-1), 3);
    EXPECT_TRUE(img->metadata().compute_ms.has_value());
    EXPECT_NE(img->metadata().tool.find("filter-phlm"), std::string::npos);
  }
  auto dbg = read_exr((dir / "phlm.0002.exr").string());
  ASSERT_TRUE(dbg);
  EXPECT_TRUE(dbg->plane("debug.traceP"));
  EXPECT_TRUE(dbg->plane("debug.alpha"));
  EXPECT_TRUE(dbg->plane("debug.reset"));
}

TEST(FilterPhlmCli, ResumeFromStateIsBitExact) {
  const auto dir = test::scratch_dir("filter-phlm-cli-resume");
  write_sequence(dir, 6);
  const std::string common = tool() + " --input " + (dir / "color.####.exr").string() + " --gbuffer " +
                             (dir / "gbuffer.####.exr").string() + " --method phlm";
  std::string out;
  ASSERT_EQ(test::run_command(common + " --out " + (dir / "whole.####.exr").string(), &out), 0) << out;
  ASSERT_EQ(test::run_command(common + " --frames 0-2 --out " + (dir / "part.####.exr").string() +
                                  " --state-out " + (dir / "state.####.exr").string(), &out), 0) << out;
  ASSERT_TRUE(fs::exists(dir / "state.0000.exr"));
  ASSERT_EQ(test::run_command(common + " --frames 3-5 --out " + (dir / "part.####.exr").string() +
                                  " --state-in " + (dir / "state.0002.exr").string(), &out), 0) << out;
  for (const char* f : {"0003", "0005"}) {
    auto a = read_exr((dir / (std::string("whole.") + f + ".exr")).string());
    auto b = read_exr((dir / (std::string("part.") + f + ".exr")).string());
    ASSERT_TRUE(a && b);
    for (const char* c : {"R", "G", "B"})
      EXPECT_EQ(std::memcmp(a->plane(c), b->plane(c), a->pixel_count() * sizeof(float)), 0) << f << " " << c;
  }
  auto state = read_exr((dir / "state.0002.exr").string());
  ASSERT_TRUE(state);
  EXPECT_TRUE(state->plane("beta.R3"));
  EXPECT_TRUE(state->plane("P.D3"));
  EXPECT_TRUE(state->plane("Pmat.P33"));
}

TEST(FilterPhlmCli, ResetFramesAndNonFiniteInput) {
  const auto dir = test::scratch_dir("filter-phlm-cli-reset");
  write_sequence(dir, 4);
  // A NaN and an Inf in frame 1: counted and reported, never in the output or the state.
  auto f1 = read_exr((dir / "color.0001.exr").string());
  ASSERT_TRUE(f1);
  f1->plane("R")[5] = NAN;
  f1->plane("B")[17] = INFINITY;
  ASSERT_TRUE(write_exr((dir / "color.0001.exr").string(), *f1));
  std::string out;
  const std::string cmd = tool() + " --input " + (dir / "color.####.exr").string() + " --gbuffer " +
                          (dir / "gbuffer.####.exr").string() + " --out " + (dir / "p.####.exr").string() +
                          " --reset-frames 3 --state-out " + (dir / "s.exr").string();
  ASSERT_EQ(test::run_command(cmd, &out), 0) << out;
  EXPECT_NE(out.find("color.0001.exr: warning: 2 pixels hold NaN, Inf or a magnitude above 1e10"), std::string::npos) << out;
  auto p1 = read_exr((dir / "p.0001.exr").string());
  ASSERT_TRUE(p1);
  for (const char* c : {"R", "G", "B"})
    for (std::size_t i = 0; i < p1->pixel_count(); ++i) ASSERT_TRUE(std::isfinite(p1->plane(c)[i]));
  // Frame 3 is a listed reset: every model restarts from the input, so the output is the input.
  auto in3 = read_exr((dir / "color.0003.exr").string());
  auto p3 = read_exr((dir / "p.0003.exr").string());
  ASSERT_TRUE(in3 && p3);
  for (const char* c : {"R", "G", "B"})
    for (std::size_t i = 0; i < p3->pixel_count(); ++i) EXPECT_NEAR(p3->plane(c)[i], in3->plane(c)[i], 1e-5f);
  // --state-out without a placeholder: the last frame's state only.
  auto state = read_exr((dir / "s.exr").string());
  ASSERT_TRUE(state);
  EXPECT_EQ(state->metadata().frame.value_or(-1), 3);
}

TEST(FilterPhlmCli, ErrorsAndExitCodes) {
  const auto dir = test::scratch_dir("filter-phlm-cli-errors");
  write_sequence(dir, 2);
  const std::string in = " --input " + (dir / "color.####.exr").string();
  std::string out;
  EXPECT_EQ(test::run_command(tool() + in + " --out " + (dir / "o.####.exr").string() + " --layer ssao", &out), 2);
  EXPECT_NE(out.find("filter-phlm: "), std::string::npos) << out;
  EXPECT_EQ(test::run_command(tool() + " --input " + (dir / "missing.####.exr").string() + " --out " +
                                  (dir / "o.####.exr").string(), &out), 2) << out;
  EXPECT_EQ(test::run_command(tool() + in + " --out " + (dir / "o.####.exr").string() + " --method fxaa --state-out " +
                                  (dir / "s.exr").string(), &out), 1) << out;
  EXPECT_EQ(test::run_command(tool() + in + " --out " + (dir / "o.####.exr").string() + " --method nope", &out), 1);
  // The wording every method tool shares, with the closest name (temporal/core/suggest.h).
  EXPECT_EQ(test::run_command(tool() + in + " --out " + (dir / "o.####.exr").string() + " --method phml", &out), 1);
  EXPECT_NE(out.find("--method 'phml' is not one of: phlm, taa, ema, fxaa (did you mean 'phlm'?)"), std::string::npos)
      << out;
  // A G-buffer without motion.
  Image g(12, 10);
  g.add_channel("depth.Z", 1.0f);
  ASSERT_TRUE(write_exr((dir / "bad.0000.exr").string(), g));
  ASSERT_TRUE(write_exr((dir / "bad.0001.exr").string(), g));
  EXPECT_EQ(test::run_command(tool() + in + " --gbuffer " + (dir / "bad.####.exr").string() + " --out " +
                                  (dir / "o.####.exr").string(), &out), 2);
  EXPECT_NE(out.find("motion"), std::string::npos) << out;
}

// Issue 11: no output replaces an input, non-finite and out-of-range options are usage errors, a state that is
// not positive definite is refused, and no input file changes in any of these runs.
TEST(FilterPhlmCli, BadRunsLoseNothing) {
  const auto dir = test::scratch_dir("filter-phlm-cli-lose-nothing");
  write_sequence(dir, 3);
  const auto checksum = [&] {
    std::string all;
    for (const char* f : {"color.0000.exr", "color.0001.exr", "color.0002.exr", "gbuffer.0001.exr"}) {
      std::ifstream in(dir / f, std::ios::binary);
      all += std::string(std::istreambuf_iterator<char>(in), {});
    }
    return std::hash<std::string>{}(all);
  };
  const auto before = checksum();
  const std::string in = " --input " + (dir / "color.####.exr").string();
  const std::string g = " --gbuffer " + (dir / "gbuffer.####.exr").string();
  std::string out;
  for (const char* m : {"phlm", "taa", "ema", "fxaa"}) {
    EXPECT_EQ(test::run_command(tool() + in + g + " --method " + std::string(m) + " --out " + (dir / "color.####.exr").string(),
                                &out), 1) << m << out;
    EXPECT_NE(out.find("one of this run's inputs"), std::string::npos) << out;
  }
  EXPECT_EQ(test::run_command(tool() + in + g + " --out " + (dir / "gbuffer.%04d.exr").string(), &out), 1) << out;
  for (const char* bad : {"--lambda nan", "--lambda inf", "--p-init -1", "--taa-alpha 2", "--ema-alpha nan",
                                 "--feature-a nan", "--threads -1"}) {
    EXPECT_EQ(test::run_command(tool() + in + " --out " + (dir / "o.####.exr").string() + " " + std::string(bad), &out), 1) << bad;
    EXPECT_LT(out.size(), 400u) << out;  // a readable range, never a 309-digit bound
  }
  // A state with a P that is not positive definite: refused before it can turn the next frame into NaN.
  ASSERT_EQ(test::run_command(tool() + in + g + " --frames 0-0 --out " + (dir / "s.####.exr").string() +
                                  " --state-out " + (dir / "state.exr").string(), &out), 0) << out;
  auto state = read_exr((dir / "state.exr").string());
  ASSERT_TRUE(state);
  state->plane("P.D0")[3] = -1e30f;
  ASSERT_TRUE(write_exr((dir / "bad_state.exr").string(), *state));
  EXPECT_EQ(test::run_command(tool() + in + g + " --frames 1-2 --out " + (dir / "r.####.exr").string() +
                                  " --state-in " + (dir / "bad_state.exr").string(), &out), 2) << out;
  EXPECT_NE(out.find("positive definite"), std::string::npos) << out;
  EXPECT_EQ(checksum(), before);
}

// --list-methods and --list-methods-json print the registry (pipelines/filter-phlm.sh and the workflow read them).
TEST(FilterPhlmCli, ListMethodsPrintsTheRegistry) {
  std::string out;
  ASSERT_EQ(test::run_command(tool() + " --list-methods 2>/dev/null", &out), 0) << out;
  std::string expected;
  for (const MethodEntry* e : registry()) expected += test::list_methods_line(*e);
  EXPECT_EQ(out, expected);
  EXPECT_NE(out.find("\tcpu,gpu\n"), std::string::npos) << "every filter has a GPU kernel: " << out;
  ASSERT_EQ(test::run_command(tool() + " --list-methods-json 2>/dev/null", &out), 0) << out;
  EXPECT_NE(out.find("{\"name\": \"phlm\", \"method\": \"phlm\", \"args\": [], \"summary\": "), std::string::npos)
      << out;
  EXPECT_NE(out.find("\"stateful\": true, \"implementations\": [\"cpu\", \"gpu\"]}"), std::string::npos) << out;
  EXPECT_NE(out.find("{\"name\": \"fxaa\""), std::string::npos) << out;
  EXPECT_NE(out.find("\"stateful\": false, " + test::device_lists(*find_entry("fxaa")).second + "}"), std::string::npos)
      << "fxaa is spatial: " << out;
}

// Issue 26 item 12: a finite colour of FLT_MAX (3.4e38) in one frame is no sample, as NaN is (temporal/core/image.h
// kMaxSampleMagnitude): it is warned about, and no method writes a non-finite value in that frame or later ones
// (phlm's RLS update once overflowed and wrote 864 of them in three frames). The state too stays finite.
TEST(FilterPhlmCli, AHugeFiniteColourIsNoSample) {
  const auto dir = test::scratch_dir("filter-phlm-cli-flt-max");
  write_sequence(dir, 5);
  auto f1 = read_exr((dir / "color.0001.exr").string());
  ASSERT_TRUE(f1);
  for (const char* c : {"R", "G", "B"})
    for (std::size_t i : {std::size_t(5), std::size_t(40), std::size_t(41)}) f1->plane(c)[i] = 3.4e38f;
  f1->plane("G")[77] = -3.4e38f;
  ASSERT_TRUE(write_exr((dir / "color.0001.exr").string(), *f1));
  for (const std::string m : {"phlm", "taa", "ema", "fxaa"}) {
    std::string out;
    const bool stateful = m != "fxaa";
    const std::string cmd = tool() + " --input " + (dir / "color.####.exr").string() + " --gbuffer " +
                            (dir / "gbuffer.####.exr").string() + " --out " + (dir / (m + ".####.exr")).string() +
                            " --method " + m + " --debug-layers" +
                            (stateful ? " --state-out " + (dir / (m + "-state.####.exr")).string() : std::string());
    ASSERT_EQ(test::run_command(cmd, &out), 0) << cmd << "\n" << out;
    EXPECT_NE(out.find("color.0001.exr: warning: 4 pixels hold NaN, Inf or a magnitude above 1e10"), std::string::npos)
        << out;
    for (int t = 0; t < 5; ++t) {
      char name[64];
      std::snprintf(name, sizeof name, "%s.%04d.exr", m.c_str(), t);
      auto img = read_exr((dir / name).string());
      ASSERT_TRUE(img) << img.error().message;
      for (const auto& c : img->channel_names())
        for (std::size_t i = 0; i < img->pixel_count(); ++i)
          ASSERT_TRUE(std::isfinite(img->plane(c)[i])) << name << " " << c << " pixel " << i;
      if (!stateful) continue;
      std::snprintf(name, sizeof name, "%s-state.%04d.exr", m.c_str(), t);
      auto state = read_exr((dir / name).string());
      ASSERT_TRUE(state) << state.error().message;
      for (const auto& c : state->channel_names())
        if (const float* p = state->plane(c)) {
          for (std::size_t i = 0; i < state->pixel_count(); ++i) ASSERT_TRUE(std::isfinite(p[i])) << name << " " << c;
        }
    }
  }
}

}  // namespace
