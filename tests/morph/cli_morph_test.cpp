// The morph-120hz command line: frame numbering and timing of the output, metadata, bad input exit codes.
#include "temporal/io/exr.h"
#include "temporal/morph/methods.h"

#include "synthetic.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <utility>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <functional>
#include <limits>

namespace temporal::morph {
namespace {

class MorphCli : public ::testing::Test {
 protected:
  void SetUp() override {
    // One folder per test: CTest runs the tests of this fixture in parallel processes.
    dir_ = test::scratch_dir(std::string("morph_cli_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    for (int n = 0; n < 2; ++n) {
      Image c = test::make_color(32, 24, [n](float x, float y, int ch) { return test::texture(x - 3.0f * n, y, ch); });
      c.metadata().fps = 40.0;
      c.metadata().frame = n;
      ASSERT_TRUE(write_exr((dir_ / ("color." + std::to_string(1000 + n).substr(1) + ".exr")).string(), c));
      Image g = test::make_gbuffer(32, 24, [](int, int, float& mx, float& my, float& d) { mx = -3.0f; my = 0.0f; d = 2.0f; });
      ASSERT_TRUE(write_exr((dir_ / ("gbuffer." + std::to_string(1000 + n).substr(1) + ".exr")).string(), g));
      Image nm(32, 24);
      nm.add_channel("depth.Z", 1.0f);
      ASSERT_TRUE(write_exr((dir_ / ("nomotion." + std::to_string(1000 + n).substr(1) + ".exr")).string(), nm));
    }
  }
  std::string tool() const { return test::tool_path("morph-120hz").string(); }
  std::string in(const std::string& name) const { return (dir_ / (name + ".###.exr")).string(); }
  std::filesystem::path dir_;
};

TEST_F(MorphCli, WritesFactorFramesPerInputWithDisplayRateTiming) {
  std::string out;
  const std::string cmd = tool() + " --input " + in("color") + " --gbuffer " + in("gbuffer") + " --out " +
                          (dir_ / "didyk" / "o.####.exr").string() + " --method didyk --debug-layers";
  ASSERT_EQ(test::run_command(cmd, &out), 0) << out;
  for (int f = 0; f < 6; ++f) ASSERT_TRUE(std::filesystem::exists(dir_ / "didyk" / ("o.000" + std::to_string(f) + ".exr")));
  auto info = read_exr_info((dir_ / "didyk" / "o.0004.exr").string());
  ASSERT_TRUE(info);
  ASSERT_TRUE(info->metadata.fps);
  EXPECT_DOUBLE_EQ(*info->metadata.fps, 120.0);
  EXPECT_EQ(*info->metadata.frame, 4);
  EXPECT_NEAR(*info->metadata.time, 4.0 / 120.0, 1e-6);  // stored as float
  EXPECT_TRUE(info->metadata.compute_ms.has_value());
  EXPECT_EQ(info->metadata.extra.at("latencyFrames"), "0");
  auto img = read_exr((dir_ / "didyk" / "o.0004.exr").string());
  ASSERT_TRUE(img);
  EXPECT_TRUE(img->has_channel("debug.blur"));
  EXPECT_TRUE(img->has_channel("debug.Hprime"));

  ASSERT_EQ(test::run_command(tool() + " --input " + in("color") + " --out " + (dir_ / "blend" / "o.####.exr").string() +
                                  " --method blend", &out), 0) << out;
  info = read_exr_info((dir_ / "blend" / "o.0002.exr").string());
  ASSERT_TRUE(info);
  EXPECT_EQ(info->metadata.extra.at("latencyFrames"), "3") << "one rendered frame = 3 output frames at factor 3";
  ASSERT_EQ(test::run_command(tool() + " --input " + in("color") + " --out " + (dir_ / "blend2" / "o.####.exr").string() +
                                  " --method blend --factor 2", &out), 0) << out;
  info = read_exr_info((dir_ / "blend2" / "o.0002.exr").string());
  ASSERT_TRUE(info);
  EXPECT_EQ(info->metadata.extra.at("latencyFrames"), "2") << "one rendered frame = 2 output frames at factor 2";

  // The perceived-blur mode runs on the upsampled sequence (display rate) with a display-rate motion.
  ASSERT_EQ(test::run_command(tool() + " --perceive --input " + (dir_ / "blend" / "o.####.exr").string() +
                                  " --gbuffer " + in("gbuffer") + " --frames 0-1 --out " +
                                  (dir_ / "perceived" / "p.####.exr").string(), &out), 0) << out;
  EXPECT_TRUE(std::filesystem::exists(dir_ / "perceived" / "p.0001.exr"));
}

TEST_F(MorphCli, BadInputExitCodes) {
  std::string out;
  EXPECT_EQ(test::run_command(tool() + " --input " + in("color") + " --gbuffer " + in("nomotion") + " --out " +
                                  (dir_ / "x" / "o.####.exr").string(), &out), 2) << out;
  EXPECT_NE(out.find("motion"), std::string::npos) << out;
  EXPECT_NE(out.find("nomotion.000.exr"), std::string::npos) << out;
  EXPECT_EQ(test::run_command(tool() + " --input " + in("color") + " --gbuffer " + in("gbuffer") + " --factor 1 --out " +
                                  (dir_ / "x" / "o.####.exr").string(), &out), 1) << out;
  EXPECT_NE(out.find("factor"), std::string::npos) << out;
  EXPECT_EQ(test::run_command(tool() + " --input " + in("color") + " --out " + (dir_ / "x" / "o.####.exr").string() +
                                  " --method didyk", &out), 1) << out;
  EXPECT_NE(out.find("--gbuffer"), std::string::npos) << out;
}

// An inverted flag clears its default-on field: with every in-between frame fully blurred (--min-blur 1) the
// rendered slot carries the compensating high frequencies, unless --no-compensation turns them off (then slot 0 is
// the input, bit for bit).
TEST_F(MorphCli, NoCompensationFlagClearsTheDefaultOnField) {
  auto slot0_differs_from_input = [&](const std::string& extra, const std::string& name) {
    std::string out;
    const std::string cmd = tool() + " --input " + in("color") + " --gbuffer " + in("gbuffer") + " --frames 0-0 --out " +
                            (dir_ / name / "o.####.exr").string() + " --min-blur 1" + extra;
    EXPECT_EQ(test::run_command(cmd, &out), 0) << out;
    auto a = read_exr((dir_ / name / "o.0000.exr").string());
    auto b = read_exr((dir_ / "color.000.exr").string());
    if (!a || !b) return -1;
    int differ = 0;
    for (std::size_t i = 0; i < b->pixel_count(); ++i) differ += a->plane("R")[i] != b->plane("R")[i];
    return differ;
  };
  EXPECT_GT(slot0_differs_from_input("", "compensated"), 0);
  EXPECT_EQ(slot0_differs_from_input(" --no-compensation", "plain"), 0);
}

// The method list scripts read (pipelines/morph-120hz.sh) is the registry's, one
// `name<TAB>arguments<TAB>summary<TAB>devices` per line as in every method tool; the JSON form adds statefulness,
// implementations and latency.
TEST_F(MorphCli, ListMethodsPrintsTheRegistry) {
  std::string out;
  ASSERT_EQ(test::run_command(tool() + " --list-methods 2>/dev/null", &out), 0) << out;
  std::string expected;
  for (const MethodEntry* e : registry()) expected += test::list_methods_line(*e);
  EXPECT_EQ(out, expected);
  EXPECT_NE(out.find("\tcpu,gpu\n"), std::string::npos) << "blend and warp have GPU kernels: " << out;
  ASSERT_EQ(test::run_command(tool() + " --list-methods-json 2>/dev/null", &out), 0) << out;
  EXPECT_NE(out.find("{\"name\": \"blend\", \"method\": \"blend\", \"args\": [], \"summary\": "), std::string::npos)
      << out;
  EXPECT_NE(out.find("\"stateful\": false, \"implementations\": [\"cpu\", \"gpu\"], \"latency_frames\": 1}"),
            std::string::npos)
      << out;
  for (const MethodEntry* e : registry())
    EXPECT_NE(out.find(test::device_lists(*e).second + ", \"latency_frames\": " +
                       std::to_string(*e->info.latency_frames) + "}"),
              std::string::npos)
        << e->info.name << ": " << out;
}

// --device gpu for a method without a GPU kernel, and for --perceive (which runs on the CPU only), is a usage error
// that says what to do.
TEST_F(MorphCli, DeviceGpuWithoutAKernelIsAUsageError) {
  const std::string base = tool() + " --input " + in("color") + " --gbuffer " + in("gbuffer") + " --out " +
                           (dir_ / "x" / "o.####.exr").string();
  std::string out;
  EXPECT_EQ(test::run_command(base + " --method repeat --device gpu", &out), 1) << out;
  EXPECT_NE(out.find("--method repeat has no gpu implementation (it runs on: cpu): pass --device cpu"),
            std::string::npos)
      << out;
  EXPECT_EQ(test::run_command(base + " --method blend --device tpu", &out), 1) << out;
  EXPECT_NE(out.find("--device"), std::string::npos) << out;
  EXPECT_EQ(test::run_command(base + " --perceive --device gpu", &out), 1) << out;
  EXPECT_NE(out.find("--perceive runs on the CPU only: drop --device gpu"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "x")) << "nothing is written";
}

TEST_F(MorphCli, OutOfRangeAndNonFiniteParametersAreUsageErrors) {
  const std::string base = tool() + " --input " + in("color") + " --gbuffer " + in("gbuffer") + " --out " +
                           (dir_ / "x" / "o.####.exr").string();
  std::string out;
  EXPECT_EQ(test::run_command(base + " --min-blur 2", &out), 1) << out;
  EXPECT_NE(out.find("--min-blur 2 is out of range: it must be [0, 1]"), std::string::npos) << out;
  EXPECT_EQ(test::run_command(base + " --gamma nan", &out), 1) << out;
  EXPECT_NE(out.find("--gamma"), std::string::npos) << out;
  EXPECT_EQ(test::run_command(base + " --method bilinear", &out), 1) << out;
  EXPECT_EQ(test::run_command(base + " --grid 6", &out), 1) << out;
  EXPECT_NE(out.find("power of two"), std::string::npos) << out;
  // Debug layers are data: DWA (lossy on `*.Y`) is refused like in every sequence tool.
  EXPECT_EQ(test::run_command(base + " --compression dwaa", &out), 1) << out;
  EXPECT_NE(out.find("dwaa"), std::string::npos) << out;
  EXPECT_EQ(test::run_command(base + " --gamma 2.4 --display srgb_display", &out), 1) << out;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "x")) << "nothing is written on a usage error";
}

// Issue 26 items 7 and 13: output frame numbers past 99,999,999 (they wrapped to negative names) and an
// infinite temporal:fps in a header are input errors naming the file; nothing is written.
TEST_F(MorphCli, OverflowingFrameNumbersAndInfiniteHeaderRatesAreRefused) {
  Image c = test::make_color(32, 24, [](float x, float y, int ch) { return test::texture(x, y, ch); });
  c.metadata().fps = 40.0;
  ASSERT_TRUE(write_exr((dir_ / "big.99999998.exr").string(), c));
  std::string out;
  EXPECT_EQ(test::run_command(tool() + " --input " + (dir_ / "big.########.exr").string() + " --out " +
                                  (dir_ / "big_out" / "m.#########.exr").string() + " --method repeat --factor 32",
                              &out),
            2)
      << out;
  EXPECT_NE(out.find("big.99999998.exr"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "big_out") && !std::filesystem::is_empty(dir_ / "big_out"));
  c.metadata().fps = std::numeric_limits<double>::infinity();
  ASSERT_TRUE(write_exr((dir_ / "inf.0000.exr").string(), c));
  EXPECT_EQ(test::run_command(tool() + " --input " + (dir_ / "inf.####.exr").string() + " --out " +
                                  (dir_ / "inf_out" / "m.####.exr").string() + " --method repeat",
                              &out),
            2)
      << out;
  EXPECT_NE(out.find("temporal:fps"), std::string::npos) << out;
}

// Issue 26 item 2: --out naming the --lag-reference sequence overwrote it; the lag reference is an input of the
// run, so that is refused (exit 1) and the files are unchanged.
TEST_F(MorphCli, TheLagReferenceIsProtectedAsAnInput) {
  for (const char* n : {"000", "001"})
    std::filesystem::copy_file(dir_ / ("color." + std::string(n) + ".exr"), dir_ / ("lag." + std::string(n) + ".exr"));
  const auto checksum = [&] {
    std::string all;
    for (const char* f : {"lag.000.exr", "lag.001.exr"}) {
      std::ifstream in(dir_ / f, std::ios::binary);
      all += std::string(std::istreambuf_iterator<char>(in), {});
    }
    return std::hash<std::string>{}(all);
  };
  const auto before = checksum();
  std::string out;
  EXPECT_EQ(test::run_command(tool() + " --perceive --input " + in("color") + " --gbuffer " + in("gbuffer") +
                                  " --lag-reference " + in("lag") + " --out " + (dir_ / "lag.%03d.exr").string(),
                              &out),
            1)
      << out;
  EXPECT_NE(out.find("lag"), std::string::npos) << out;
  EXPECT_EQ(checksum(), before);
}

// Issue 26 item 13: --ppd 1e-40 lay inside the accepted [0, 10000] and made the eye-tracking limit's fps / ppd
// infinite (NaN outputs). --ppd and --fps are 0 (derived / read from the header) or in a range whose arithmetic stays
// finite; --help says which. The smallest accepted --ppd gives finite outputs.
TEST_F(MorphCli, ViewingOptionsHaveFiniteRangesAndTheirEndsGiveFiniteOutputs) {
  const std::string base = tool() + " --input " + in("color") + " --gbuffer " + in("gbuffer") + " --method didyk";
  std::string out;
  for (const char* bad : {"--ppd 1e-40", "--ppd 0.001", "--ppd 1e5", "--fps 1e-40", "--fps 1e-4", "--ppd inf"}) {
    EXPECT_EQ(test::run_command(base + " --out " + (dir_ / "x" / "o.####.exr").string() + " " + bad, &out), 1) << bad;
    EXPECT_NE(out.find(std::string(bad).substr(0, 5)), std::string::npos) << out;
  }
  EXPECT_NE(out.find("must be a finite number"), std::string::npos) << out;
  ASSERT_EQ(test::run_command(base + " --out " + (dir_ / "x" / "o.####.exr").string() + " --ppd 1e-40", &out), 1);
  // (The float field holds 1e-40 as the denormal 9.99995e-41, which the message prints.)
  EXPECT_NE(out.find("is out of range: it must be 0 or [0.01, 10000]"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "x")) << "nothing is written on a usage error";
  ASSERT_EQ(test::run_command(tool() + " --help", &out), 0);
  EXPECT_NE(out.find("0 or [0.01, 10000]"), std::string::npos) << "--help names the range";
  for (const char* edge : {"--ppd 0.01", "--ppd 10000", "--ppd 0.01 --fps 10000", "--fps 0.001"}) {
    const std::string name = std::string("edge") + std::to_string(std::hash<std::string>{}(edge) % 1000);
    ASSERT_EQ(test::run_command(base + " --out " + (dir_ / name / "o.####.exr").string() + " " + edge, &out), 0)
        << edge << "\n" << out;
    for (int f = 0; f < 6; ++f) {
      auto img = read_exr((dir_ / name / ("o.000" + std::to_string(f) + ".exr")).string());
      ASSERT_TRUE(img) << edge << " " << f;
      for (const auto& c : img->channel_names())
        for (std::size_t i = 0; i < img->pixel_count(); ++i)
          ASSERT_TRUE(std::isfinite(img->plane(c)[i])) << edge << " frame " << f << " " << c;
    }
  }
}

}  // namespace
}  // namespace temporal::morph
