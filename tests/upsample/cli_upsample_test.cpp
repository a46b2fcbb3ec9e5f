// The upsample-st tool end to end on a small generated sequence: outputs and headers, --reset-frames,
// exit codes for bad input.
#include "synthetic.h"

#include "temporal/io/exr.h"
#include "temporal/upsample/methods.h"
#include "temporal/upsample/upsample.h"

#include <gtest/gtest.h>
#include <test_support.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <string>

using temporal::test::make_frame;
using temporal::test::SyntheticScene;
namespace fs = std::filesystem;

namespace {

fs::path write_sequence(const std::string& name, int frames, bool drop_motion = false) {
  const fs::path dir = temporal::test::scratch_dir(name);
  SyntheticScene scene;
  scene.object = true;
  scene.object_velocity = {2.0f, 1.0f};
  for (int t = 0; t < frames; ++t) {
    auto f = make_frame(scene, t);
    if (drop_motion) {
      f.gbuffer.remove_channel("motion.X");
      f.gbuffer.remove_channel("motion.Y");
    }
    char num[16];
    std::snprintf(num, sizeof num, "%04d", t);
    EXPECT_TRUE(temporal::write_exr((dir / ("gbuffer." + std::string(num) + ".exr")).string(), f.gbuffer));
    EXPECT_TRUE(temporal::write_exr((dir / ("shade." + std::string(num) + ".exr")).string(), f.low));
  }
  return dir;
}

std::string tool() { return temporal::test::tool_path("upsample-st").string(); }

}  // namespace

TEST(UpsampleCli, WritesFramesWithHeaders) {
  const fs::path dir = write_sequence("upsample_cli", 4);
  for (const char* method : {"spatial", "temporal", "herzog", "drobot", "taau"}) {
    std::string output;
    const std::string cmd = tool() + " --gbuffer " + (dir / "gbuffer.####.exr").string() + " --input " +
                            (dir / "shade.####.exr").string() + " --out " + (dir / method).string() +
                            ".####.exr --method " + method + " --debug-layers --reset-frames 2";
    ASSERT_EQ(temporal::test::run_command(cmd, &output), 0) << output;
    for (int t = 0; t < 4; ++t) {
      char num[16];
      std::snprintf(num, sizeof num, "%04d", t);
      auto img = temporal::read_exr((dir / (std::string(method) + "." + num + ".exr")).string());
      ASSERT_TRUE(img.has_value()) << img.error().message;
      EXPECT_EQ(img->width(), 64);
      EXPECT_TRUE(img->has_channel("R") && img->has_channel("debug.confidence"));
      const auto& md = img->metadata();
      ASSERT_TRUE(md.compute_ms.has_value());
      EXPECT_GT(*md.compute_ms, 0.0);
      EXPECT_NE(md.tool.find("upsample-st"), std::string::npos);
      EXPECT_NE(md.parameters.find("--method"), std::string::npos);
      ASSERT_TRUE(md.extra.count("holePixels"));
      if (std::string(method) != "spatial") {
        // Frames 0 (first) and 2 (--reset-frames) have no history: every pixel counted.
        const long holes = std::stol(md.extra.at("holePixels"));
        if (t == 0 || t == 2) {
          EXPECT_EQ(md.camera_cut.value_or(false), true) << method << " frame " << t;
        }
        if (t == 3) {
          EXPECT_LT(holes, 64 * 48 / 2) << method;
        }
      }
    }
  }
}

TEST(UpsampleCli, HeaderRecordsTheMethodParameters) {
  // `temporal:methodParameters`: every parameter of the method with its value, defaults included (issue 15: a
  // and the cap of gamma w_f), so that make_options of it reproduces the run's options.
  const fs::path dir = write_sequence("upsample_cli_params", 2);
  std::string output;
  const std::string cmd = tool() + " --gbuffer " + (dir / "gbuffer.####.exr").string() + " --input " +
                          (dir / "shade.####.exr").string() + " --out " + (dir / "h.####.exr").string() +
                          " --method herzog --a 0.7 --max-kernel-gamma 8";
  ASSERT_EQ(temporal::test::run_command(cmd, &output), 0) << output;
  auto img = temporal::read_exr((dir / "h.0001.exr").string());
  ASSERT_TRUE(img.has_value()) << img.error().message;
  ASSERT_TRUE(img->metadata().extra.count("methodParameters"));
  const std::string text = img->metadata().extra.at("methodParameters");
  for (const char* expected : {"--a 0.7", "--max-kernel-gamma 8", "--kernel-gamma 4", "--fallback spatial"})
    EXPECT_NE((" " + text + " ").find(std::string(" ") + expected + " "), std::string::npos) << expected << " in " << text;
  EXPECT_EQ(text.find("--favor-spatial"), std::string::npos) << "flags appear only when on: " << text;
  std::vector<std::string> args;
  std::stringstream in(text);
  for (std::string a; in >> a;) args.push_back(a);
  auto o = temporal::upsample::make_options("herzog", args);
  ASSERT_TRUE(o.has_value()) << o.error().message;
  EXPECT_EQ(temporal::upsample::method_parameters(*o), text);
  // A method without parameters writes none.
  ASSERT_EQ(temporal::test::run_command(tool() + " --gbuffer " + (dir / "gbuffer.####.exr").string() + " --input " +
                                            (dir / "shade.####.exr").string() + " --out " +
                                            (dir / "s.####.exr").string() + " --method spatial",
                                        &output),
            0)
      << output;
  auto s = temporal::read_exr((dir / "s.0001.exr").string());
  ASSERT_TRUE(s.has_value());
  EXPECT_EQ(s->metadata().extra.count("methodParameters"), 0u);
}

TEST(UpsampleCli, BadInputExitCodes) {
  const fs::path dir = write_sequence("upsample_cli_bad", 2, /*drop_motion=*/true);
  std::string output;
  const std::string base = tool() + " --gbuffer " + (dir / "gbuffer.####.exr").string() + " --input " +
                           (dir / "shade.####.exr").string() + " --out " + (dir / "o.####.exr").string();
  EXPECT_EQ(temporal::test::run_command(base + " --method herzog", &output), 2) << output;
  EXPECT_NE(output.find("motion"), std::string::npos) << output;
  // The spatial method does not need motion vectors.
  EXPECT_EQ(temporal::test::run_command(base + " --method spatial", &output), 0) << output;
  EXPECT_EQ(temporal::test::run_command(base + " --method nonsense", &output), 1) << output;
  EXPECT_EQ(temporal::test::run_command(base + " --method spatial --layer ssao", &output), 2) << output;
}

TEST(UpsampleCli, StateFilesResumeBitIdentically) {
  // Frames 0-5 in one run, and as two runs chained by --state-out / --state-in (the way a long sequence runs as a
  // chain of jobs): frames 3-5 must be the same files, pixel for pixel.
  const fs::path dir = write_sequence("upsample_cli_state", 6);
  const std::string base = tool() + " --gbuffer " + (dir / "gbuffer.####.exr").string() + " --input " +
                           (dir / "shade.####.exr").string() + " --debug-layers";
  for (const temporal::upsample::MethodVariant& v : temporal::upsample::method_variants()) {
    std::string args = " --method " + v.method;
    for (const auto& a : v.args) args += " " + a;
    std::string output;
    const fs::path whole = dir / (v.name + "_whole"), parts = dir / (v.name + "_parts");
    const std::string state = (dir / (v.name + ".state.exr")).string();
    const std::string first = base + args + " --out " + (parts / "o.####.exr").string() + " --frames 0-2";
    if (!temporal::upsample::find_entry(v.method)->info.has_state) {
      EXPECT_EQ(temporal::test::run_command(first + " --state-out " + state, &output), 1) << output;
      EXPECT_NE(output.find("no state"), std::string::npos) << output;
      continue;
    }
    ASSERT_EQ(temporal::test::run_command(base + args + " --out " + (whole / "o.####.exr").string(), &output), 0)
        << output;
    ASSERT_EQ(temporal::test::run_command(first + " --state-out " + state, &output), 0) << output;
    ASSERT_EQ(temporal::test::run_command(base + args + " --out " + (parts / "o.####.exr").string() +
                                              " --frames 3-5 --state-in " + state,
                                          &output),
              0)
        << output;
    for (const char* frame : {"0003", "0004", "0005"}) {
      auto a = temporal::read_exr((whole / ("o." + std::string(frame) + ".exr")).string());
      auto b = temporal::read_exr((parts / ("o." + std::string(frame) + ".exr")).string());
      ASSERT_TRUE(a && b) << v.name;
      ASSERT_EQ(a->channel_names(), b->channel_names()) << v.name;
      std::size_t differ = 0;
      for (const auto& c : a->channel_names())
        if (const float *pa = a->plane(c), *pb = b->plane(c); pa && pb)
          for (std::size_t i = 0; i < a->pixel_count(); ++i) differ += std::memcmp(pa + i, pb + i, 4) != 0;
      EXPECT_EQ(differ, 0u) << v.name << " frame " << frame;
      // The resumed run does not restart its history: the header says so.
      EXPECT_FALSE(b->metadata().camera_cut.value_or(false)) << v.name << " frame " << frame;
    }
    // A state resumed at a frame other than the next one is refused (its history belongs to frame 2).
    EXPECT_EQ(temporal::test::run_command(base + args + " --out " + (dir / "x.####.exr").string() +
                                              " --frames 4-5 --state-in " + state,
                                          &output),
              1)
        << output;
    EXPECT_NE(output.find("--frames 3-"), std::string::npos) << output;
    // A state of another method is refused with exit code 1 and names both methods.
    const std::string other = v.method == "temporal" ? "herzog" : "temporal";
    EXPECT_EQ(temporal::test::run_command(base + " --method " + other + " --out " + (dir / "x.####.exr").string() +
                                              " --frames 3-5 --state-in " + state,
                                          &output),
              1)
        << output;
    EXPECT_NE(output.find("--method " + v.method), std::string::npos) << output;
  }
}

// A --state-in file whose history holds a NaN (a damaged file: --state-out never writes one) stops the run before
// it writes anything, with exit code 2 (bad input) and a message that names the file and the channel; the intact
// file resumes (tests/upsample/state_test.cpp has every method and channel).
TEST(UpsampleCli, DamagedStateIsRefused) {
  const fs::path dir = write_sequence("upsample_cli_damaged_state", 5);
  const std::string base = tool() + " --gbuffer " + (dir / "gbuffer.####.exr").string() + " --input " +
                           (dir / "shade.####.exr").string() + " --method temporal";
  const std::string state = (dir / "state.exr").string(), damaged = (dir / "damaged.exr").string();
  std::string output;
  const std::string first = base + " --out " + (dir / "a.####.exr").string() + " --frames 0-2 --state-out " + state;
  ASSERT_EQ(temporal::test::run_command(first, &output), 0) << output;
  auto image = temporal::read_exr(state);
  ASSERT_TRUE(image.has_value());
  ASSERT_NE(image->plane("history.R"), nullptr);
  image->plane("history.R")[image->width() + 1] = std::nanf("");
  ASSERT_TRUE(temporal::write_exr(damaged, *image));
  const fs::path out = dir / "b";
  const std::string resume = base + " --out " + (out / "b.####.exr").string() + " --frames 3-4 --state-in ";
  EXPECT_EQ(temporal::test::run_command(resume + damaged, &output), 2) << output;
  EXPECT_NE(output.find("'history.R'"), std::string::npos) << output;
  EXPECT_NE(output.find("damaged.exr"), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(out / "b.0003.exr")) << output;
  EXPECT_EQ(temporal::test::run_command(resume + state, &output), 0) << output;
}

TEST(UpsampleCli, ListMethods) {
  std::string output;
  ASSERT_EQ(temporal::test::run_command(tool() + " --list-methods", &output), 0) << output;
  // One tab-separated line per method and variant: name, arguments, summary, devices.
  for (const temporal::upsample::MethodVariant& v : temporal::upsample::method_variants())
    EXPECT_NE(output.find(v.name + "\t--method " + v.method), std::string::npos) << output;
  EXPECT_NE(output.find("herzog-lagged\t--method herzog --lagged-wf\t"), std::string::npos) << output;
  EXPECT_NE(output.find("*-demod\t--demodulate\t"), std::string::npos) << output;
  for (const temporal::upsample::MethodEntry* e : temporal::upsample::registry())
    EXPECT_NE(output.find(temporal::test::list_methods_line(*e)), std::string::npos) << e->info.name << ": " << output;
  // The machine-readable form (temporal/core/method.h, apps/common/method_list.h): one object per method and
  // variant with its statefulness and implementations, then the name suffixes.
  ASSERT_EQ(temporal::test::run_command(tool() + " --list-methods-json", &output), 0) << output;
  EXPECT_NE(output.find("{\"name\": \"spatial\", \"method\": \"spatial\", \"args\": [], \"summary\": "),
            std::string::npos)
      << output;
  // Every upsampling method has its C++ implementation and its GLSL kernels (docs/gpu.md).
  EXPECT_NE(output.find("\"stateful\": false, \"implementations\": [\"cpu\", \"gpu\"]}"), std::string::npos) << output;
  EXPECT_NE(output.find("{\"name\": \"herzog-lagged\", \"method\": \"herzog\", \"args\": [\"--lagged-wf\"]"),
            std::string::npos)
      << output;
  EXPECT_NE(output.find("{\"suffix\": \"-demod\", \"args\": [\"--demodulate\"]"), std::string::npos) << output;
  EXPECT_EQ(output.find("latency_frames"), std::string::npos) << "upsample-st has no notion of latency";
}

// An unknown method names the choices and the closest one (the same wording in every method tool).
TEST(UpsampleCli, UnknownMethodSuggestsTheClosest) {
  std::string output;
  EXPECT_EQ(temporal::test::run_command(tool() + " --gbuffer g.####.exr --input s.####.exr --out o.####.exr "
                                                 "--method herzg",
                                        &output),
            1);
  EXPECT_NE(output.find("--method 'herzg' is not one of: spatial, temporal, herzog, drobot, taau (did you mean "
                        "'herzog'?)"),
            std::string::npos)
      << output;
}

namespace {
// Non-finite values in every float plane of an output frame (outputs and debug layers alike).
std::size_t non_finite_values(const temporal::Image& img) {
  std::size_t n = 0;
  for (const auto& c : img.channel_names())
    if (const float* p = img.plane(c))
      for (std::size_t i = 0; i < img.pixel_count(); ++i) n += std::isfinite(p[i]) ? 0 : 1;
  return n;
}
// Payload values (R, G, B) that are no sample: non-finite or past kMaxSampleMagnitude (temporal/core/image.h).
std::size_t unusable_payload_values(const temporal::Image& img) {
  std::size_t n = 0;
  for (const char* c : {"R", "G", "B"})
    if (const float* p = img.plane(c))
      for (std::size_t i = 0; i < img.pixel_count(); ++i) n += temporal::usable_sample(p[i]) ? 0 : 1;
  return n;
}
}  // namespace

// Issue 26 items 11 and 12: a G-buffer frame with NaN depth (64 pixels), a shade frame with a finite FLT_MAX
// sample and one with a 1e20 sample are warned about and treated as missing by every method: no non-finite value
// in any output, debug layers included, and no payload value past kMaxSampleMagnitude, in that frame or the ones
// after it. drobot once wrote thousands (its Listing 7.2 confidence of a NaN cached depth was NaN and entered the
// frame count of the cache); drobot --mode refresh wrote the 1e20 sample's neighbourhood (Listing 7.1's fallback
// read it) and carried it in its history.
TEST(UpsampleCli, NonFiniteDepthAndHugeSamplesNeverReachTheOutputs) {
  const fs::path dir = write_sequence("upsample_cli_hostile_values", 5);
  {
    auto g = temporal::read_exr((dir / "gbuffer.0001.exr").string());
    ASSERT_TRUE(g.has_value());
    float* z = g->plane("depth.Z");
    for (int y = 12; y < 20; ++y)  // an 8x8 square: block centres of the cache and the taps beside them
      for (int x = 20; x < 28; ++x) z[std::size_t(y) * std::size_t(g->width()) + std::size_t(x)] = NAN;
    ASSERT_TRUE(temporal::write_exr((dir / "gbuffer.0001.exr").string(), *g));
    auto s = temporal::read_exr((dir / "shade.0002.exr").string());
    ASSERT_TRUE(s.has_value());
    for (const char* c : {"R", "G", "B"}) s->plane(c)[5] = 3.4e38f;
    ASSERT_TRUE(temporal::write_exr((dir / "shade.0002.exr").string(), *s));
    auto s3 = temporal::read_exr((dir / "shade.0003.exr").string());
    ASSERT_TRUE(s3.has_value());
    s3->plane("R")[std::size_t(s3->width()) * 3 + 7] = 1e20f;
    ASSERT_TRUE(temporal::write_exr((dir / "shade.0003.exr").string(), *s3));
  }
  for (const std::string method : {"spatial", "temporal", "herzog", "drobot", "drobot --mode refresh", "taau"}) {
    std::string output;
    const std::string name = method == "drobot --mode refresh" ? "refresh" : method;
    const std::string cmd = tool() + " --gbuffer " + (dir / "gbuffer.####.exr").string() + " --input " +
                            (dir / "shade.####.exr").string() + " --out " + (dir / name).string() +
                            ".####.exr --debug-layers --method " + method;
    ASSERT_EQ(temporal::test::run_command(cmd, &output), 0) << output;
    EXPECT_NE(output.find("gbuffer.0001.exr: warning: 64 pixels hold NaN or Inf"), std::string::npos) << output;
    for (const char* frame : {"shade.0002.exr", "shade.0003.exr"})
      EXPECT_NE(output.find(std::string(frame) + ": warning: 1 pixels hold NaN, Inf or a magnitude above 1e10"),
                std::string::npos)
          << output;
    for (int t = 0; t < 5; ++t) {
      char num[16];
      std::snprintf(num, sizeof num, "%04d", t);
      auto img = temporal::read_exr((dir / (name + "." + num + ".exr")).string());
      ASSERT_TRUE(img.has_value()) << img.error().message;
      EXPECT_EQ(non_finite_values(*img), 0u) << method << " frame " << t;
      EXPECT_EQ(unusable_payload_values(*img), 0u) << method << " frame " << t;
    }
  }
}
