// The upsample-st tool end to end on a small generated sequence: outputs and headers, --reset-frames,
// exit codes for bad input.
#include "synthetic.h"

#include "temporal/core/exr.h"

#include <gtest/gtest.h>
#include <test_support.h>

#include <cstdio>
#include <filesystem>
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
  for (const char* method : {"spatial", "temporal", "herzog", "drobot"}) {
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
