// Every layer and metadata attribute of docs/conventions.md survives a write and a read bit for bit.
#include "temporal/io/exr.h"

#include "test_support.h"

#include <glm/gtc/matrix_transform.hpp>

#include <OpenImageIO/imageio.h>

#include <cstring>
#include <fstream>
#include <regex>
#include <set>

namespace temporal {
namespace {

// The float channels the conventions table names (the uint `id` is checked separately).
const std::vector<std::string> kFloatChannels = {
    "R",        "G",        "B",        "A",        "depth.Z",  "N.X",      "N.Y",      "N.Z",     "motion.X",
    "motion.Y", "prevDepth.Z", "albedo.R", "albedo.G", "albedo.B", "direct.R", "direct.G", "direct.B", "shadow.Y", "ssao.Y",
    "gi.R",     "gi.G",     "gi.B",     "error.R",  "error.G",  "error.B",  "error.Y"};

bool bit_equal(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(Conventions, EveryLayerRoundTripsBitForBit) {
  const auto dir = test::scratch_dir("conventions");
  Image image(13, 7);
  std::uint32_t seed = 12345;
  for (const auto& c : kFloatChannels) {
    float* p = image.add_channel(c);
    for (std::size_t i = 0; i < image.pixel_count(); ++i) {
      seed = seed * 1664525u + 1013904223u;
      p[i] = (float(seed >> 8) / float(1 << 24) - 0.5f) * 1000.0f;  // full float32 mantissas
    }
  }
  std::uint32_t* id = image.add_uint_channel("id");
  for (std::size_t i = 0; i < image.pixel_count(); ++i) id[i] = 0xFFFFFFF0u - std::uint32_t(i);

  FrameMetadata& md = image.metadata();
  const glm::mat4 view = glm::lookAt(glm::vec3(1, 2, 3), glm::vec3(0), glm::vec3(0, 1, 0));
  const glm::mat4 proj = glm::perspective(0.8f, 13.0f / 7.0f, 0.1f, 50.0f);
  md.world_to_camera = view;
  md.world_to_ndc = proj * view;
  md.near_clip = 0.1f;
  md.far_clip = 50.0f;
  md.frame = 42;
  md.fps = 40.0;
  md.time = 42.0 / 40.0;
  md.jitter = glm::vec2(-0.375f, 0.125f);
  md.jitter_factor = 4;
  md.jitter_index = 10;
  md.camera_cut = true;
  md.compute_ms = 3.25;
  md.tool = "conventions_test 1";
  md.parameters = "--a 1 --b 'x y'";
  md.timings_ms["gbuffer"] = 1.5;
  md.timings_ms["shadeLow"] = 2.5;
  md.extra["latencyFrames"] = "1";

  const std::string path = (dir / "all.0042.exr").string();
  ASSERT_TRUE(write_exr(path, image));
  auto back = read_exr(path);
  ASSERT_TRUE(back) << back.error().message;
  for (const auto& c : kFloatChannels) {
    ASSERT_NE(back->plane(c), nullptr) << c;
    for (std::size_t i = 0; i < image.pixel_count(); ++i)
      ASSERT_TRUE(bit_equal(back->plane(c)[i], image.plane(c)[i])) << c << " pixel " << i;
  }
  ASSERT_EQ(back->channel_type("id"), ChannelType::UInt);
  for (std::size_t i = 0; i < image.pixel_count(); ++i) ASSERT_EQ(back->uint_plane("id")[i], id[i]);

  const FrameMetadata& m = back->metadata();
  ASSERT_TRUE(m.world_to_camera && m.world_to_ndc);
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) {
      EXPECT_EQ((*m.world_to_camera)[c][r], view[c][r]);
      EXPECT_EQ((*m.world_to_ndc)[c][r], (proj * view)[c][r]);
    }
  EXPECT_EQ(*m.near_clip, 0.1f);
  EXPECT_EQ(*m.far_clip, 50.0f);
  EXPECT_EQ(*m.frame, 42);
  EXPECT_EQ(*m.fps, 40.0);
  EXPECT_FLOAT_EQ(float(*m.time), 1.05f);
  EXPECT_EQ(m.jitter->x, -0.375f);
  EXPECT_EQ(m.jitter->y, 0.125f);
  EXPECT_EQ(*m.jitter_factor, 4);
  EXPECT_EQ(*m.jitter_index, 10);
  EXPECT_TRUE(*m.camera_cut);
  EXPECT_EQ(*m.compute_ms, 3.25);
  EXPECT_EQ(m.tool, "conventions_test 1");
  EXPECT_EQ(m.parameters, "--a 1 --b 'x y'");
  EXPECT_EQ(m.timings_ms.at("gbuffer"), 1.5);
  EXPECT_EQ(m.timings_ms.at("shadeLow"), 2.5);
  EXPECT_EQ(m.extra.at("latencyFrames"), "1");

  // The matrices are OpenEXR's standard attributes, in OpenEXR's row-vector layout: a world point times
  // the stored matrix (row vector on the left) gives the camera-space point.
  auto in = OIIO::ImageInput::open(path);
  const OIIO::ParamValue* p = in->spec().find_attribute("worldToCamera", OIIO::TypeMatrix44);
  ASSERT_NE(p, nullptr);
  const float* rows = static_cast<const float*>(p->data());
  const glm::vec4 world(0.5f, -1.0f, 2.0f, 1.0f);
  const glm::vec4 expected = view * world;
  for (int j = 0; j < 4; ++j) {
    float v = 0.0f;
    for (int i = 0; i < 4; ++i) v += world[i] * rows[i * 4 + j];
    EXPECT_NEAR(v, expected[j], 1e-5f);
  }
}

// The conventions document and this test name the same layers.
TEST(Conventions, DocumentNamesEveryTestedLayer) {
  std::ifstream doc(test::source_dir() / "docs" / "conventions.md");
  ASSERT_TRUE(doc) << "docs/conventions.md is missing";
  const std::string text((std::istreambuf_iterator<char>(doc)), std::istreambuf_iterator<char>());
  for (const auto& c : kFloatChannels) {
    const auto dot = c.find('.');
    if (dot == std::string::npos) continue;  // bare colour channels: checked as `R,G,B` below
    const std::string layer = c.substr(0, dot);
    EXPECT_NE(text.find("`" + layer), std::string::npos) << "docs/conventions.md does not name " << layer;
  }
  EXPECT_NE(text.find("`id`"), std::string::npos);
  EXPECT_NE(text.find("`R,G,B`"), std::string::npos);
  for (const char* attr : {"worldToCamera", "worldToNDC", "clipNear", "clipFar", "temporal:frame", "temporal:fps",
                           "temporal:time", "temporal:jitter", "temporal:jitterFactor", "temporal:cameraCut",
                           "temporal:computeMs", "temporal:tool", "temporal:parameters", "temporal:ms:"})
    EXPECT_NE(text.find(attr), std::string::npos) << attr;
}

}  // namespace
}  // namespace temporal
