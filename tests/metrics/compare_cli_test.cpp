// The built `compare` tool, run as a pipeline would: DISPLAY unset (compare must provide its own Xvfb), CSV
// rows, JSON keys, PNG files, exit codes for thresholds and bad input, and every option of --help accepted.
#include "temporal/io/exr.h"
#include "temporal/core/image.h"

#include "test_support.h"

#include <sys/stat.h>

#include <OpenImageIO/imageio.h>
#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>

namespace temporal {
namespace {

namespace fs = std::filesystem;

Image noisy(int w, int h, unsigned seed, float amount, const Image* base) {
  Image img(w, h);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-amount, amount);
  for (const char* c : {"R", "G", "B"}) {
    float* p = img.add_channel(c);
    for (std::size_t i = 0; i < img.pixel_count(); ++i) {
      const float x = float(i % std::size_t(w)) / float(w), y = float(i / std::size_t(w)) / float(h);
      p[i] = (base ? base->plane(c)[i] : 0.5f + 0.4f * std::sin(6.0f * x + 3.0f * y)) + u(rng);
    }
  }
  return img;
}

// True for a PNG file with a valid signature and an IHDR of the expected size.
::testing::AssertionResult is_png(const fs::path& path, int width, int height) {
  if (!fs::exists(path)) return ::testing::AssertionFailure() << path << " does not exist";
  const auto bytes = test::read_file(path);
  static const std::string sig("\x89PNG\r\n\x1a\n", 8);
  if (bytes.size() < 33 || bytes.compare(0, 8, sig) != 0 || bytes.compare(12, 4, "IHDR") != 0)
    return ::testing::AssertionFailure() << path << " is not a PNG (" << bytes.size() << " bytes)";
  auto be32 = [&](std::size_t at) {
    return (std::uint32_t(std::uint8_t(bytes[at])) << 24) | (std::uint32_t(std::uint8_t(bytes[at + 1])) << 16) |
           (std::uint32_t(std::uint8_t(bytes[at + 2])) << 8) | std::uint32_t(std::uint8_t(bytes[at + 3]));
  };
  if (int(be32(16)) != width || int(be32(20)) != height)
    return ::testing::AssertionFailure() << path << " is " << be32(16) << "x" << be32(20);
  return ::testing::AssertionSuccess();
}

class CompareCli : public ::testing::Test {
 protected:
  void SetUp() override {
    tool_ = test::tool_path("compare").string();
    if (!fs::exists(tool_)) GTEST_FAIL() << "compare is not built at " << tool_;
    dir_ = test::scratch_dir(std::string("compare-cli-") +
                             ::testing::UnitTest::GetInstance()->current_test_info()->name());
    for (int f = 1; f <= 3; ++f) {
      char digits[8];
      std::snprintf(digits, sizeof digits, "%04d", f);
      Image ref = noisy(64, 40, 1, 0.0f, nullptr);
      Image a = noisy(64, 40, unsigned(10 + f), 0.02f, &ref);
      Image b = noisy(64, 40, unsigned(20 + f), 0.1f, &ref);
      a.metadata().compute_ms = 1.5;
      b.metadata().compute_ms = 0.5;
      b.metadata().timings_ms["filter"] = 0.4;
      ASSERT_TRUE(write_exr((dir_ / (std::string("ref.") + digits + ".exr")).string(), ref));
      ASSERT_TRUE(write_exr((dir_ / (std::string("a.") + digits + ".exr")).string(), a));
      ASSERT_TRUE(write_exr((dir_ / (std::string("b.") + digits + ".exr")).string(), b));
      Image g(64, 40);
      g.add_channel("motion.X", 0.0f);
      g.add_channel("motion.Y", 0.0f);
      ASSERT_TRUE(write_exr((dir_ / (std::string("g.") + digits + ".exr")).string(), g));
    }
  }
  int run(const std::string& args, std::string* out = nullptr) {
    return test::run_command("cd " + dir_.string() + " && env -u DISPLAY " + tool_ + " " + args, out);
  }
  std::string tool_;
  fs::path dir_;
};

TEST_F(CompareCli, WritesCsvJsonAndPngWithoutDisplay) {
  const bool have_xvfb = test::run_command("command -v Xvfb >/dev/null") == 0;
  std::string out;
  const int code = run("--reference ref.####.exr a.####.exr b.####.exr --names good,noisy --csv m.csv --json m.json "
                       "--plot plots/p.png --verbose --flip ldr", &out);
  if (have_xvfb) {
    EXPECT_EQ(code, 0) << out;
    EXPECT_NE(out.find("started Xvfb"), std::string::npos) << out;  // said only with --verbose
    for (const char* name : {"p.png", "p-psnr-y.png", "p-ssim.png", "p-flicker.png", "p-flip.png", "p-speed.png"})
      EXPECT_TRUE(is_png(dir_ / "plots" / name, 1280, 720)) << out;
  } else {
    // No Xvfb: a clear error and exit 4, but CSV and JSON are written.
    EXPECT_EQ(code, 4) << out;
    EXPECT_NE(out.find("Xvfb"), std::string::npos) << out;
  }
  // CSV: header + 3 frames x 2 sequences.
  const auto csv = test::read_file(dir_ / "m.csv");
  std::istringstream lines(csv);
  std::string line;
  std::vector<std::string> rows;
  while (std::getline(lines, line)) rows.push_back(line);
  ASSERT_EQ(rows.size(), 7u) << csv;
  EXPECT_EQ(rows[0].rfind("frame,sequence,psnr_rgb_db,psnr_y_db,ssim,flicker,", 0), 0u) << rows[0];
  EXPECT_EQ(rows[1].rfind("1,good,", 0), 0u);
  EXPECT_EQ(rows[6].rfind("3,noisy,", 0), 0u);
  // JSON summary.
  const auto j = nlohmann::json::parse(test::read_file(dir_ / "m.json"));
  for (const char* key : {"tool", "reference", "frames", "peak", "thresholds", "passed", "sequences"})
    EXPECT_TRUE(j.contains(key)) << key;
  ASSERT_EQ(j["sequences"].size(), 2u);
  EXPECT_EQ(j["sequences"][0]["name"], "good");
  for (const char* key : {"psnr_rgb", "psnr_y", "ssim", "flicker", "flip"}) {
    EXPECT_TRUE(j["sequences"][1][key].contains("mean")) << key;
    EXPECT_TRUE(j["sequences"][1][key].contains("min")) << key;
  }
  EXPECT_GT(j["sequences"][0]["psnr_rgb"]["mean"].get<double>(), j["sequences"][1]["psnr_rgb"]["mean"].get<double>());
  EXPECT_EQ(j["sequences"][1]["compute_ms"], 0.5);
  EXPECT_EQ(j["frames"]["count"], 3);
  EXPECT_EQ(j["passed"], true);
}

TEST_F(CompareCli, WithoutXvfbPlotsFailWithExitFourButCsvAndJsonAreWritten) {
  std::string out;
  // An empty PATH hides Xvfb (compare itself is run by its full path).
  const int code = test::run_command("cd " + dir_.string() + " && env -u DISPLAY PATH=/nonexistent " + tool_ +
                                         " --reference ref.####.exr a.####.exr --csv m.csv --json m.json --plot p.png",
                                     &out);
  EXPECT_EQ(code, 4) << out;
  EXPECT_NE(out.find("compare: p.png: cannot draw the plots: DISPLAY is unset and Xvfb is not installed"),
            std::string::npos) << out;
  EXPECT_TRUE(fs::exists(dir_ / "m.csv"));
  EXPECT_TRUE(fs::exists(dir_ / "m.json"));
  EXPECT_FALSE(fs::exists(dir_ / "p.png"));
}

TEST_F(CompareCli, ThresholdsGiveExitThree) {
  std::string out;
  // good: uniform noise 0.02 -> PSNR ~39.5 dB; noisy: 0.1 -> ~25.5 dB.
  EXPECT_EQ(run("--reference ref.####.exr a.####.exr --fail-psnr 30", &out), 0) << out;
  EXPECT_EQ(run("--reference ref.####.exr a.####.exr b.####.exr --fail-psnr 30 --json t.json", &out), 3) << out;
  EXPECT_NE(out.find("b: psnr_rgb"), std::string::npos) << out;
  const auto j = nlohmann::json::parse(test::read_file(dir_ / "t.json"));
  EXPECT_EQ(j["passed"], false);
  EXPECT_EQ(j["failures"][0]["sequence"], "b");
  EXPECT_EQ(run("--reference ref.####.exr a.####.exr --fail-ssim 0.9999", &out), 3) << out;
  EXPECT_EQ(run("--reference ref.####.exr b.####.exr --fail-flicker 0.001 --fail-on worst", &out), 3) << out;
  // FLIP: noise of 0.1 is clearly visible, 0.02 much less; the stdout table gains a flip column.
  EXPECT_EQ(run("--reference ref.####.exr a.####.exr b.####.exr --flip ldr --fail-flip 0.9", &out), 0) << out;
  EXPECT_NE(out.find("flip"), std::string::npos) << out;
  EXPECT_EQ(run("--reference ref.####.exr a.####.exr b.####.exr --flip hdr --ppd 30 --fail-flip 0.001", &out), 3) << out;
  EXPECT_NE(out.find("b: flip"), std::string::npos) << out;
}

TEST_F(CompareCli, FlipOptionErrorsAreUsageErrors) {
  std::string out;
  EXPECT_EQ(run("--reference ref.####.exr a.####.exr --fail-flip 0.1", &out), 1) << out;  // FLIP is off
  EXPECT_NE(out.find("--flip ldr"), std::string::npos) << out;
  EXPECT_EQ(run("--reference ref.####.exr a.####.exr --flip sometimes", &out), 1) << out;
  // A choice names the values it takes (Param tables, not CLI11's "Check ... FAILED").
  EXPECT_NE(out.find("compare: --flip 'sometimes' is not one of: off, ldr, hdr"), std::string::npos) << out;
  EXPECT_EQ(run("--reference ref.####.exr a.####.exr --flip ldr --ppd 0", &out), 1) << out;
}

TEST_F(CompareCli, ExitCodesForUsageErrors) {
  std::string out;
  EXPECT_EQ(run("--reference ref.####.exr", &out), 1) << out;                                // no test
  EXPECT_EQ(run("--reference ref.####.exr a.####.exr --bogus", &out), 1) << out;            // unknown option
  EXPECT_EQ(run("--reference ref.####.exr a.####.exr --peak -2", &out), 1) << out;          // bad value
  EXPECT_EQ(run("--reference ref.####.exr a.####.exr --frames 3-1", &out), 1) << out;
  EXPECT_EQ(run("--reference ref.####.exr a.####.exr --names x,y", &out), 1) << out;
}

TEST_F(CompareCli, ExitCodesForInputErrors) {
  std::string out;
  EXPECT_EQ(run("--reference ref.####.exr missing.####.exr", &out), 2) << out;              // missing files
  EXPECT_NE(out.find("compare: "), std::string::npos);
  EXPECT_EQ(run("--reference ref.####.exr a.####.exr --layer albedo", &out), 2) << out;     // missing layer
  EXPECT_NE(out.find("albedo"), std::string::npos) << out;
  EXPECT_EQ(run("--reference nothing.####.exr a.####.exr", &out), 2) << out;                // empty sequence
  fs::resize_file(dir_ / "a.0002.exr", 100);
  EXPECT_EQ(run("--reference ref.####.exr a.####.exr", &out), 2) << out;                    // truncated
  EXPECT_NE(out.find("a.0002.exr"), std::string::npos) << out;
}

TEST_F(CompareCli, HelpListsEveryOptionAndEachIsAccepted) {
  std::string help;
  ASSERT_EQ(run("--help", &help), 0);
  std::string version;
  ASSERT_EQ(run("--version", &version), 0);
  EXPECT_NE(version.find("compare "), std::string::npos);
  // Every option documented in --help, fed to the parser in one run (without --plot to stay fast).
  const std::array<std::pair<const char*, const char*>, 23> options = {{
      {"--reference", "ref.####.exr"}, {"--names", "one"}, {"--csv", "all.csv"}, {"--json", "all.json"},
      {"--gbuffer", "g.####.exr"}, {"--mask", "R"}, {"--layer", "rgb"}, {"--reference-layer", "rgb"},
      {"--error-maps", "maps"}, {"--frames", "1-2"}, {"--peak", "max"}, {"--flip", "ldr"}, {"--ppd", "50"},
      {"--fail-psnr", "1"}, {"--fail-ssim", "0"}, {"--fail-flicker", "100"}, {"--fail-flip", "1"},
      {"--fail-on", "worst"}, {"--threads", "1"}, {"--verbose", ""}, {"--plot", ""}, {"--help", ""},
      {"--speed-metric", "ssim"}}};
  std::string args;
  for (const auto& [name, value] : options) {
    EXPECT_NE(help.find(name), std::string::npos) << name << " is not in --help";
    if (std::string(name) == "--plot" || std::string(name) == "--help") continue;
    args += std::string(" ") + name + (*value ? std::string(" ") + value : std::string());
  }
  EXPECT_NE(help.find("Exit codes"), std::string::npos);
  EXPECT_NE(help.find("--peak TEXT=1"), std::string::npos) << "--peak default not shown";
  EXPECT_NE(help.find("=off"), std::string::npos) << "--flip default not shown";
  EXPECT_NE(help.find("67.0206"), std::string::npos) << "--ppd default not shown";
  for (const char* group : {"\nInputs:\n", "\nMetrics:\n", "\nOutputs:\n", "\nPictures:\n", "\nThresholds:\n"})
    EXPECT_NE(help.find(group), std::string::npos) << group << "is not a section of --help";
  std::string out;
  EXPECT_EQ(run(args + " a.####.exr", &out), 0) << args << "\n" << out;
  EXPECT_TRUE(fs::exists(dir_ / "maps" / "one.0002.exr"));
  EXPECT_FALSE(fs::exists(dir_ / "maps" / "one.0003.exr"));  // --frames 1-2
  const auto csv = test::read_file(dir_ / "all.csv");
  EXPECT_NE(csv.find("psnr_rgb_in_db"), std::string::npos);  // --mask columns
  EXPECT_NE(csv.find("flip_in"), std::string::npos);         // FLIP's, with --flip and --mask
  auto maps = read_exr((dir_ / "maps" / "one.0002.exr").string());
  ASSERT_TRUE(maps) << maps.error().message;
  EXPECT_NE(maps->plane("error.flip"), nullptr);
}

// Issue 11: no output replaces an input (exit 1, nothing changed), overflowing values are reported and can fail
// the run, non-finite thresholds are usage errors; and the JSON carries intervals and paired differences.
TEST_F(CompareCli, BadRunsLoseNothingAndOverflowIsReported) {
  auto checksum = [&] {
    std::string all;
    for (const char* f : {"ref.0001.exr", "a.0001.exr", "a.0002.exr", "b.0003.exr", "g.0001.exr"})
      all += test::read_file(dir_ / f);
    return std::hash<std::string>{}(all);
  };
  const auto before = checksum();
  std::string out;
  for (const std::string args : {"--csv ref.0001.exr", "--json a.0002.exr", "--plot a.0003.exr",
                                 "--error-maps . --names a", "--error-maps ./ --names x,b"}) {
    const std::string tests = args.find("x,b") != std::string::npos ? " a.####.exr b.####.exr" : " a.####.exr";
    EXPECT_EQ(run("--reference ref.####.exr" + tests + " --gbuffer g.####.exr " + args, &out), 1) << args << out;
    // A chart is never an .exr: --plot refuses the extension before it could name an input.
    const char* why = args.rfind("--plot", 0) == 0 ? ".png, .svg or .pdf" : "one of this run's inputs";
    EXPECT_NE(out.find(why), std::string::npos) << out;
  }
  EXPECT_EQ(run("--reference ref.####.exr a.####.exr --fail-psnr nan", &out), 1) << out;
  EXPECT_EQ(checksum(), before);
  // A broken output with huge finite values: PSNR -inf, said per frame; --fail-nonfinite turns it into exit 3.
  auto a2 = read_exr((dir_ / "a.0002.exr").string());
  ASSERT_TRUE(a2);
  a2->plane("G")[100] = 1e30f;
  ASSERT_TRUE(write_exr((dir_ / "c.0001.exr").string(), *a2));
  ASSERT_TRUE(write_exr((dir_ / "c.0002.exr").string(), *a2));
  ASSERT_TRUE(write_exr((dir_ / "c.0003.exr").string(), *a2));
  EXPECT_EQ(run("--reference ref.####.exr c.####.exr", &out), 0) << out;
  EXPECT_NE(out.find("is -inf"), std::string::npos) << out;
  EXPECT_EQ(run("--reference ref.####.exr c.####.exr --fail-nonfinite", &out), 3) << out;
  EXPECT_NE(out.find("3 frames"), std::string::npos) << out;
  // Intervals and paired differences in the JSON.
  ASSERT_EQ(run("--reference ref.####.exr a.####.exr b.####.exr --warmup 1 --json s.json", &out), 0) << out;
  const auto j = nlohmann::json::parse(test::read_file(dir_ / "s.json"));
  const auto& psnr = j["sequences"][0]["psnr_rgb"];
  ASSERT_TRUE(psnr["ci95"].is_array());
  EXPECT_LE(psnr["ci95"][0].get<double>(), psnr["mean"].get<double>());
  EXPECT_GE(psnr["ci95"][1].get<double>(), psnr["mean"].get<double>());
  EXPECT_EQ(psnr["steady"]["frames"].get<int>(), 2);
  bool found = false;
  for (const auto& p : j["paired"])
    if (p["a"] == "a" && p["b"] == "b" && p["metric"] == "psnr_rgb") {
      found = true;
      EXPECT_GT(p["mean_difference"].get<double>(), 5.0);  // noise 0.02 against 0.1: about 14 dB apart
      EXPECT_GT(p["ci95"][0].get<double>(), 0.0);
    }
  EXPECT_TRUE(found);
}

// Issue 14: a comparison run as shards (disjoint --frames ranges) and merged gives exactly the single run's
// means and intervals; each shard primes its first frame's flicker from the frame before it.
TEST_F(CompareCli, ShardsMergeIntoTheSingleRunExactly) {
  std::string out;
  const std::string common = "--reference ref.####.exr a.####.exr b.####.exr --gbuffer g.####.exr --warmup 1";
  ASSERT_EQ(run(common + " --json whole.json --csv whole.csv", &out), 0) << out;
  ASSERT_EQ(run(common + " --frames 1-1 --csv s1.csv", &out), 0) << out;
  ASSERT_EQ(run(common + " --frames 2-3 --csv s2.csv", &out), 0) << out;
  const auto s2 = test::read_file(dir_ / "s2.csv");  // shown when a mean differs
  ASSERT_EQ(run("--merge s2.csv s1.csv --warmup 1 --json merged.json --csv merged.csv", &out), 0) << out;
  const auto whole = nlohmann::json::parse(test::read_file(dir_ / "whole.json"));
  const auto merged = nlohmann::json::parse(test::read_file(dir_ / "merged.json"));
  ASSERT_EQ(whole["sequences"].size(), merged["sequences"].size());
  for (std::size_t s = 0; s < whole["sequences"].size(); ++s)
    for (const char* m : {"psnr_rgb", "psnr_y", "ssim", "flicker"}) {
      const auto& w = whole["sequences"][s][m];
      const auto& g = merged["sequences"][s][m];
      EXPECT_EQ(w["frames"], g["frames"]) << m;
      EXPECT_EQ(w["mean"], g["mean"]) << m << " " << s2;  // exactly, not approximately
      EXPECT_EQ(w["ci95"], g["ci95"]) << m;
      EXPECT_EQ(w["steady"], g["steady"]) << m;
    }
  EXPECT_EQ(whole["paired"], merged["paired"]);
  // Overlapping shards are refused.
  EXPECT_EQ(run("--merge s1.csv whole.csv --json x.json", &out), 2) << out;
  EXPECT_NE(out.find("two shards"), std::string::npos) << out;
  // Pictures and the report need the frames: refused with --merge before anything is written.
  for (const std::string extra : {"--report rep", "--png pngs", "--error-maps maps"}) {
    EXPECT_EQ(run("--merge s2.csv s1.csv --json never.json " + extra, &out), 1) << extra << "\n" << out;
    EXPECT_NE(out.find("need the frames"), std::string::npos) << out;
    EXPECT_FALSE(fs::exists(dir_ / "never.json")) << extra;
  }
  // Without --merge a reference and a test are needed.
  EXPECT_EQ(run("--json never.json", &out), 1) << out;
  EXPECT_NE(out.find("--reference"), std::string::npos) << out;
}

// Issue 24: --regions motion with its errors (no --gbuffer, a G-buffer without depth and ids, a G-buffer of another
// size), the CSV's region rows and JSON's regions, and shards that merge into the single run (the static test looks
// back --static-frames frames, which a shard primes).
TEST_F(CompareCli, RegionsFromTheGbuffer) {
  for (int f = 1; f <= 3; ++f) {
    char digits[8];
    std::snprintf(digits, sizeof digits, "%04d", f);
    Image g(64, 40), small(32, 20);
    float* mx = g.add_channel("motion.X", 0.0f);
    g.add_channel("motion.Y", 0.0f);
    g.add_channel("depth.Z", 2.0f);
    g.add_uint_channel("id", 1);
    for (int y = 0; y < 40; ++y)
      for (int x = 40; x < 64; ++x) mx[y * 64 + x] = -0.5f;  // a moving part on the right
    for (const char* c : {"motion.X", "motion.Y", "depth.Z"}) small.add_channel(c, 0.0f);
    small.add_uint_channel("id", 1);
    ASSERT_TRUE(write_exr((dir_ / (std::string("gd.") + digits + ".exr")).string(), g));
    ASSERT_TRUE(write_exr((dir_ / (std::string("gs.") + digits + ".exr")).string(), small));
  }
  std::string out;
  EXPECT_EQ(run("--reference ref.####.exr a.####.exr --regions motion", &out), 1) << out;
  EXPECT_NE(out.find("--regions motion needs --gbuffer"), std::string::npos) << out;
  EXPECT_EQ(run("--reference ref.####.exr a.####.exr --regions motion --gbuffer g.####.exr", &out), 2) << out;
  EXPECT_NE(out.find("depth.Z"), std::string::npos) << out;
  EXPECT_EQ(run("--reference ref.####.exr a.####.exr --regions motion --gbuffer gs.####.exr", &out), 2) << out;
  EXPECT_NE(out.find("G-buffer is 32x20"), std::string::npos) << out;
  EXPECT_EQ(run("--reference ref.####.exr a.####.exr --regions plenty --gbuffer gd.####.exr", &out), 1) << out;
  EXPECT_EQ(run("--reference ref.####.exr a.####.exr --regions motion --gbuffer gd.####.exr --static-frames 0", &out), 1)
      << out;
  EXPECT_EQ(run("--reference ref.####.exr a.####.exr --regions motion --gbuffer gd.####.exr --static-tolerance -1", &out),
            1) << out;

  const std::string common =
      "--reference ref.####.exr a.####.exr b.####.exr --gbuffer gd.####.exr --regions motion --static-frames 2";
  ASSERT_EQ(run(common + " --csv r.csv --json r.json", &out), 0) << out;
  EXPECT_NE(out.find("psnr_rgb_pooled"), std::string::npos) << out;
  EXPECT_NE(out.find("static"), std::string::npos) << out;
  const auto csv = test::read_file(dir_ / "r.csv");
  std::istringstream lines(csv);
  std::string line;
  std::vector<std::string> rows;
  while (std::getline(lines, line)) rows.push_back(line);
  ASSERT_EQ(rows.size(), 1u + 3 * 2 * 4) << csv;
  EXPECT_EQ(rows[0].rfind("frame,sequence,region,region_share,psnr_rgb_db,", 0), 0u) << rows[0];
  EXPECT_EQ(rows[1].rfind("1,a,all,1,", 0), 0u) << rows[1];
  EXPECT_EQ(rows[2].rfind("1,a,static,0,", 0), 0u) << rows[2];        // no previous frame: nothing static,
  EXPECT_EQ(rows[4].rfind("1,a,disoccluded,1,", 0), 0u) << rows[4];   // everything disoccluded
  // Frame 3: still for 2 frames on the left (40 of 64 columns) -> static; the right moves.
  EXPECT_EQ(rows[18].rfind("3,a,static,0.625,", 0), 0u) << rows[18];
  EXPECT_EQ(rows[19].rfind("3,a,moving,0.375,", 0), 0u) << rows[19];
  const auto j = nlohmann::json::parse(test::read_file(dir_ / "r.json"));
  EXPECT_EQ(j["regions"]["kind"], "motion");
  EXPECT_EQ(j["regions"]["static_frames"], 2);
  const auto& regions = j["sequences"][0]["regions"];
  double share = 0.0;
  for (const char* r : {"static", "moving", "disoccluded"}) {
    ASSERT_TRUE(regions.contains(r)) << r;
    share += regions[r]["share"].get<double>();
    EXPECT_TRUE(regions[r].contains("psnr_rgb_pooled")) << r;
  }
  EXPECT_NEAR(share, 1.0, 1e-12);
  EXPECT_TRUE(j["sequences"][0].contains("psnr_rgb_pooled"));
  EXPECT_TRUE(j["sequences"][0].contains("psnr_y_pooled"));

  // Shards: frames 1-2 and 3 (primed from 1 and 2) merge into the single run exactly.
  ASSERT_EQ(run(common + " --frames 1-2 --csv s1.csv", &out), 0) << out;
  ASSERT_EQ(run(common + " --frames 3-3 --csv s2.csv", &out), 0) << out;
  ASSERT_EQ(run("--merge s1.csv s2.csv --json merged.json", &out), 0) << out;
  const auto merged = nlohmann::json::parse(test::read_file(dir_ / "merged.json"));
  for (std::size_t s = 0; s < 2; ++s) {
    EXPECT_EQ(j["sequences"][s]["regions"], merged["sequences"][s]["regions"]) << s;
    EXPECT_EQ(j["sequences"][s]["psnr_rgb_pooled"], merged["sequences"][s]["psnr_rgb_pooled"]) << s;
  }
  EXPECT_EQ(j["paired"], merged["paired"]);
  // A shard with regions and one without do not merge.
  ASSERT_EQ(run("--reference ref.####.exr a.####.exr b.####.exr --frames 3-3 --csv plain.csv", &out), 0) << out;
  EXPECT_EQ(run("--merge s1.csv plain.csv --json never.json", &out), 2) << out;
}

// Issue 21: the registry is the one list of metrics (--list-metrics), and the JSON flags the Pareto front of compute
// time against --speed-metric (the speed chart's front), so that scripts read it instead of recomputing it.
TEST_F(CompareCli, ListsMetricsAndFlagsTheParetoFront) {
  std::string out;
  ASSERT_EQ(run("--list-metrics", &out), 0) << out;
  EXPECT_EQ(out.rfind("psnr_rgb\tPSNR\tdB\thigher\n", 0), 0u) << out;
  EXPECT_NE(out.find("\nssim\tSSIM\t\thigher\n"), std::string::npos) << out;
  EXPECT_NE(out.find("\nflicker\tflicker\t\tlower\n"), std::string::npos) << out;
  ASSERT_EQ(run("--list-metrics-json", &out), 0) << out;
  const auto list = nlohmann::json::parse(out);
  ASSERT_TRUE(list.is_array());
  std::vector<std::string> names;
  for (const auto& m : list) names.push_back(m["name"]);
  EXPECT_EQ(names, (std::vector<std::string>{"psnr_rgb", "psnr_y", "ssim", "flicker", "flip", "psnr_latency"}));
  EXPECT_EQ(list[4]["better"], "lower");
  EXPECT_EQ(list[4]["highest"], 1.0);
  EXPECT_EQ(list[0]["threshold_option"], "--fail-psnr");

  // c: as noisy as b (0.1) and slower than a (2 ms against 1.5 ms): a is faster and better, so c is dominated.
  for (int f = 1; f <= 3; ++f) {
    char digits[8];
    std::snprintf(digits, sizeof digits, "%04d", f);
    auto ref = read_exr((dir_ / (std::string("ref.") + digits + ".exr")).string());
    ASSERT_TRUE(ref);
    Image c = noisy(64, 40, unsigned(30 + f), 0.1f, &*ref);
    c.metadata().compute_ms = 2.0;
    ASSERT_TRUE(write_exr((dir_ / (std::string("c.") + digits + ".exr")).string(), c));
  }
  const std::string tests = "--reference ref.####.exr a.####.exr b.####.exr c.####.exr --gbuffer g.####.exr";
  for (const std::string metric : {"psnr_rgb", "ssim", "flicker"}) {
    ASSERT_EQ(run(tests + " --json p.json --speed-metric " + metric, &out), 0) << out;
    const auto j = nlohmann::json::parse(test::read_file(dir_ / "p.json"));
    EXPECT_EQ(j["speed_metric"], metric);
    EXPECT_EQ(j["sequences"][0]["pareto"], true) << metric;   // a: the best
    EXPECT_EQ(j["sequences"][1]["pareto"], true) << metric;   // b: the fastest
    EXPECT_EQ(j["sequences"][2]["pareto"], false) << metric;  // c: slower and worse than a
  }
  EXPECT_EQ(run(tests + " --speed-metric flip", &out), 1) << out;  // not measured without --flip
  EXPECT_NE(out.find("--flip ldr"), std::string::npos) << out;
  EXPECT_EQ(run(tests + " --speed-metric psnr", &out), 1) << out;
  EXPECT_NE(out.find("--speed-metric 'psnr' is not a metric"), std::string::npos) << out;
}

// Issue 26 item 8: a --crop whose x + w overflows an int, and a --ppd that asks FLIP for filters of 1e29 taps, once
// crashed compare (SIGSEGV); both are usage errors naming the option. The FLIP range's ends run.
TEST_F(CompareCli, OverflowingCropsAndPixelsPerDegreeAreUsageErrors) {
  std::string out;
  EXPECT_EQ(run("--reference ref.####.exr a.####.exr --png pics --crop 60,60,2147483647,2147483647", &out), 1) << out;
  EXPECT_NE(out.find("--crop 60,60,2147483647,2147483647 does not fit in the 64x40 image"), std::string::npos) << out;
  EXPECT_EQ(run("--reference ref.####.exr a.####.exr --png pics --crop 2147483647,0,1,1", &out), 1) << out;
  EXPECT_NE(out.find("--crop"), std::string::npos) << out;
  // Found at the first frame, before any frame is scored: no CSV and no table (it was found when the sheet was drawn,
  // after the whole comparison had run).
  EXPECT_EQ(run("--reference ref.####.exr a.####.exr --png pics --csv crop.csv --crop 60,0,8,8", &out), 1) << out;
  EXPECT_NE(out.find("--crop 60,0,8,8 does not fit in the 64x40 image"), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(dir_ / "crop.csv")) << out;
  for (const char* ppd : {"1e30", "1001", "0.5", "1e-40", "inf"}) {
    EXPECT_EQ(run(std::string("--reference ref.####.exr a.####.exr --flip ldr --ppd ") + ppd, &out), 1) << ppd << out;
    EXPECT_NE(out.find("--ppd"), std::string::npos) << out;
  }
  EXPECT_NE(out.find("must be a finite number"), std::string::npos) << out;
  ASSERT_EQ(run("--help", &out), 0);
  EXPECT_NE(out.find("[1, 1000]"), std::string::npos) << "--help names --ppd's range";
  for (const char* ppd : {"1", "1000"}) {
    for (const char* mode : {"ldr", "hdr"}) {
      EXPECT_EQ(run(std::string("--reference ref.####.exr a.####.exr --frames 1-2 --json f.json --flip ") + mode +
                        " --ppd " + ppd,
                    &out),
                0)
          << mode << " " << ppd << out;
      const auto j = nlohmann::json::parse(test::read_file(dir_ / "f.json"));
      const auto& flip = j["sequences"][0]["flip"];
      ASSERT_TRUE(flip.is_object()) << j.dump().substr(0, 600);
      ASSERT_TRUE(flip["mean"].is_number()) << "a NaN FLIP is written as null: " << flip.dump();
      EXPECT_TRUE(std::isfinite(flip["mean"].get<double>())) << flip.dump();
    }
  }
}

// Issue 26 items 2 and 5: --csv and --json naming one file lost the CSV, and an output that was a device node was
// replaced by a regular file (exit 0). Both are refused (exit 1) before anything is written; the pipe stays a pipe.
TEST_F(CompareCli, OutputsThatAliasOrAreNotRegularFilesAreRefused) {
  std::string out;
  EXPECT_EQ(run("--reference ref.####.exr a.####.exr --csv m.txt --json m.txt", &out), 1) << out;
  EXPECT_NE(out.find("--json"), std::string::npos) << out;
  EXPECT_NE(out.find("--csv"), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(dir_ / "m.txt"));
  fs::create_directories(dir_ / "sub");
  EXPECT_EQ(run("--reference ref.####.exr a.####.exr --csv m.txt --json ./sub/../m.txt", &out), 1) << out;
  const fs::path fifo = dir_ / "pipe.csv";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_EQ(run("--reference ref.####.exr a.####.exr --csv pipe.csv", &out), 1) << out;
  EXPECT_NE(out.find("pipe.csv"), std::string::npos) << out;
  EXPECT_NE(out.find("not a regular file"), std::string::npos) << out;
  struct stat st {};
  ASSERT_EQ(::stat(fifo.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode)) << "the pipe was replaced";
  EXPECT_EQ(run("--reference ref.####.exr a.####.exr --csv /dev/null", &out), 1) << out;  // a character device
  EXPECT_NE(out.find("/dev/null"), std::string::npos) << out;
}

// Issue 26 items 6 and 8 at the command line: a test frame whose data window is shifted against its display window
// (it scored inf dB) and one whose R, G, B are stored as uint32 (SIGSEGV) are input errors (exit 2) naming the file.
TEST_F(CompareCli, ShiftedDataWindowsAndIntegerColourAreInputErrorsNamingTheFile) {
  auto write_raw = [&](const std::string& name, int x, int y, OIIO::TypeDesc type) {
    OIIO::ImageSpec spec(64 - x, 40 - y, 3, type);
    spec.x = x;
    spec.y = y;
    spec.full_width = 64;
    spec.full_height = 40;
    spec.channelnames = {"R", "G", "B"};
    auto out = OIIO::ImageOutput::create(name);
    ASSERT_TRUE(out && out->open((dir_ / name).string(), spec));
    std::vector<float> pixels(std::size_t(spec.width) * spec.height * 3, 0.25f);
    std::vector<std::uint32_t> ints(pixels.size(), 7u);
    ASSERT_TRUE(type == OIIO::TypeFloat ? out->write_image(OIIO::TypeFloat, pixels.data())
                                        : out->write_image(OIIO::TypeUInt, ints.data()));
    ASSERT_TRUE(out->close());
  };
  write_raw("shift.0001.exr", 10, 7, OIIO::TypeFloat);
  write_raw("uint.0001.exr", 0, 0, OIIO::TypeUInt);
  std::string out;
  EXPECT_EQ(run("--reference ref.####.exr shift.####.exr --frames 1-1", &out), 2) << out;
  EXPECT_NE(out.find("shift.0001.exr"), std::string::npos) << out;
  EXPECT_NE(out.find("data window"), std::string::npos) << out;
  EXPECT_EQ(run("--reference ref.####.exr uint.####.exr --frames 1-1", &out), 2) << out;
  EXPECT_NE(out.find("uint.0001.exr"), std::string::npos) << out;
  EXPECT_NE(out.find("uint"), std::string::npos) << out;
}

// Inputs that cannot be examined (a symbolic link loop) are input errors naming the file wherever compare looks
// at them, also where it checks whether the frame before a --frames range exists (it used the throwing
// std::filesystem::exists there: exit 5, "please report this").
TEST_F(CompareCli, AnInputThatCannotBeExaminedIsAnInputErrorNamingIt) {
  for (int f = 2; f <= 3; ++f)
    fs::copy_file(dir_ / ("a.000" + std::to_string(f) + ".exr"), dir_ / ("loop.000" + std::to_string(f) + ".exr"));
  fs::create_symlink("loop.0001.exr", dir_ / "loop.0001.exr");  // a link to itself
  std::string out;
  EXPECT_EQ(run("--reference ref.####.exr loop.####.exr --frames 2-3", &out), 2) << out;
  EXPECT_NE(out.find("loop.0001.exr"), std::string::npos) << out;
  EXPECT_NE(out.find("cannot be examined"), std::string::npos) << out;
  EXPECT_EQ(out.find("please report"), std::string::npos) << out;
  // The control: without the loop the frame before the range is simply absent.
  fs::remove(dir_ / "loop.0001.exr");
  EXPECT_EQ(run("--reference ref.####.exr loop.####.exr --frames 2-3", &out), 0) << out;
}

}  // namespace
}  // namespace temporal
