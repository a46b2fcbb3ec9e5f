// render-gbuffer's command line: bad input, the layers of each --outputs choice, headers, determinism.
#include "test_support.h"

#include "temporal/io/exr.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <vector>

namespace temporal {
namespace {

namespace fs = std::filesystem;

using test::base64;

// A small valid glTF: a ground quad and a tilted quad above it, animated by a translation (LINEAR).
// No camera and no light: the scene module adds an automatic camera and key light.
fs::path write_test_scene(const fs::path& dir) {
  std::vector<float> pos = {-2, 0, 2, 2, 0, 2, 2, 0, -2, -2, 0, -2,               // ground
                            -0.5f, 0.5f, 0, 0.5f, 0.5f, 0, 0.5f, 1.2f, -0.3f, -0.5f, 1.2f, -0.3f};  // panel
  std::vector<std::uint16_t> idx = {0, 1, 2, 0, 2, 3};
  std::vector<float> times = {0.0f, 1.0f};
  std::vector<float> trans = {-0.5f, 0, 0, 0.5f, 0, 0};
  std::vector<unsigned char> buf;
  auto append = [&](const void* p, std::size_t n) {
    const auto* c = static_cast<const unsigned char*>(p);
    buf.insert(buf.end(), c, c + n);
  };
  append(pos.data(), pos.size() * 4);     // 0..96
  append(idx.data(), idx.size() * 2);     // 96..108
  append(times.data(), times.size() * 4); // 108..116
  append(trans.data(), trans.size() * 4); // 116..140
  const std::string json = R"({
  "asset": {"version": "2.0"},
  "scene": 0,
  "scenes": [{"nodes": [0, 1]}],
  "nodes": [{"mesh": 0}, {"mesh": 1}],
  "meshes": [
    {"primitives": [{"attributes": {"POSITION": 0}, "indices": 2, "material": 0}]},
    {"primitives": [{"attributes": {"POSITION": 1}, "indices": 2, "material": 1}]}],
  "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1]}},
                {"pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.3, 0.2, 1]}, "doubleSided": true}],
  "animations": [{"channels": [{"sampler": 0, "target": {"node": 1, "path": "translation"}}],
                  "samplers": [{"input": 3, "output": 4, "interpolation": "LINEAR"}]}],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-2, 0, -2], "max": [2, 0, 2]},
    {"bufferView": 0, "byteOffset": 48, "componentType": 5126, "count": 4, "type": "VEC3",
     "min": [-0.5, 0.5, -0.3], "max": [0.5, 1.2, 0]},
    {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"},
    {"bufferView": 2, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0], "max": [1]},
    {"bufferView": 3, "componentType": 5126, "count": 2, "type": "VEC3"}],
  "bufferViews": [
    {"buffer": 0, "byteOffset": 0, "byteLength": 96},
    {"buffer": 0, "byteOffset": 96, "byteLength": 12},
    {"buffer": 0, "byteOffset": 108, "byteLength": 8},
    {"buffer": 0, "byteOffset": 116, "byteLength": 24}],
  "buffers": [{"byteLength": 140, "uri": "data:application/octet-stream;base64,)" +
                           base64(buf) + R"("}]
})";
  const fs::path path = dir / "scene.gltf";
  std::ofstream(path) << json;
  return path;
}

std::string tool() { return test::tool_path("render-gbuffer").string(); }

TEST(RenderCli, MalformedSceneIsAnInputError) {
  const auto dir = test::scratch_dir("render_cli_malformed");
  std::ofstream(dir / "bad.gltf") << "{ \"asset\": { \"version\": \"2.0\" }, \"nodes\": [ ";
  std::string output;
  const int rc = test::run_command(tool() + " " + (dir / "bad.gltf").string() + " --out " + (dir / "out").string() +
                                       " --size 32x24",
                                   &output);
  EXPECT_EQ(rc, 2) << output;
  EXPECT_NE(output.find("render-gbuffer: "), std::string::npos) << output;
  EXPECT_NE(output.find("bad.gltf"), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(dir / "out" / "gbuffer.0000.exr"));
}

TEST(RenderCli, MissingBufferAndUnsupportedExtensionAreInputErrors) {
  const auto dir = test::scratch_dir("render_cli_bad_gltf");
  const std::string valid = [&] {
    std::ifstream in(write_test_scene(dir));
    return std::string(std::istreambuf_iterator<char>(in), {});
  }();
  // The same scene with its buffer pointing at a file that does not exist.
  std::string missing = valid;
  const auto uri = missing.find("data:application");
  missing.replace(uri, missing.find('"', uri) - uri, "missing.bin");
  std::ofstream(dir / "missing_buffer.gltf") << missing;
  // The same scene requiring an extension nobody implements here.
  std::string ext = valid;
  ext.replace(ext.find("\"scene\": 0"), 10, "\"extensionsRequired\": [\"KHR_draco_mesh_compression\"], \"scene\": 0");
  std::ofstream(dir / "draco.gltf") << ext;
  std::string output;
  EXPECT_EQ(test::run_command(tool() + " " + (dir / "missing_buffer.gltf").string() + " --out " + (dir / "o").string(),
                              &output),
            2)
      << output;
  EXPECT_NE(output.find("missing_buffer.gltf"), std::string::npos) << output;
  EXPECT_EQ(test::run_command(tool() + " " + (dir / "draco.gltf").string() + " --out " + (dir / "o").string(), &output), 2)
      << output;
  EXPECT_NE(output.find("KHR_draco_mesh_compression"), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(dir / "o" / "gbuffer.0000.exr"));
}

TEST(RenderCli, UsdScenesRenderAndBadUsdIsRefusedWithItsPosition) {
  const auto dir = test::scratch_dir("render_cli_usd");
  std::string output;
  // The USD copy of a built-in scene renders (one frame; frames come from its timeline as for glTF).
  const std::string usda = (test::source_dir() / "assets" / "scenes" / "morph_test.usda").string();
  ASSERT_EQ(test::run_command(tool() + " " + usda + " --out " + (dir / "ok").string() +
                                  " --size 32x24 --frames 3-3 --outputs gbuffer --verbose",
                              &output),
            0)
      << output;
  EXPECT_TRUE(fs::exists(dir / "ok" / "gbuffer.0003.exr"));
  // Malformed text: exit 2, `render-gbuffer: file:line:column: what is wrong`.
  std::ofstream(dir / "bad.usda") << "#usda 1.0\ndef Mesh \"M\" {\n    float x = \"text\"\n}\n";
  EXPECT_EQ(test::run_command(tool() + " " + (dir / "bad.usda").string() + " --out " + (dir / "o").string(), &output), 2)
      << output;
  EXPECT_NE(output.find("render-gbuffer: " + (dir / "bad.usda").string() + ":3:15: "), std::string::npos) << output;
  // A crate file: exit 2 with the command that converts it.
  std::ofstream(dir / "crate.usd") << "PXR-USDC" << std::string(88, '\0');
  EXPECT_EQ(test::run_command(tool() + " " + (dir / "crate.usd").string() + " --out " + (dir / "o").string(), &output), 2)
      << output;
  EXPECT_NE(output.find("usdcat -o file.usda crate.usd"), std::string::npos) << output;
  // USD scenes have one timeline: a named clip is a usage error.
  EXPECT_EQ(test::run_command(tool() + " " + usda + " --out " + (dir / "o").string() + " --clip wave", &output), 1) << output;
  EXPECT_FALSE(fs::exists(dir / "o" / "gbuffer.0000.exr"));
}

TEST(RenderCli, MissingSceneIsAnInputError) {
  const auto dir = test::scratch_dir("render_cli_missing");
  std::string output;
  EXPECT_EQ(test::run_command(tool() + " " + (dir / "nope.glb").string() + " --out " + dir.string(), &output), 2)
      << output;
}

TEST(RenderCli, BadOptionsAreUsageErrors) {
  const auto dir = test::scratch_dir("render_cli_usage");
  const auto scene = write_test_scene(dir).string();
  std::string output;
  EXPECT_EQ(test::run_command(tool() + " " + scene + " --out " + dir.string() + " --size 64by48", &output), 1) << output;
  EXPECT_EQ(test::run_command(tool() + " " + scene + " --out " + dir.string() + " --size 64x48 --factor 5", &output), 1)
      << output;
  EXPECT_NE(output.find("--factor"), std::string::npos) << output;
  EXPECT_EQ(test::run_command(tool() + " " + scene + " --out " + dir.string() + " --payload direct,foo", &output), 1)
      << output;
  EXPECT_EQ(test::run_command(tool() + " " + scene + " --out " + dir.string() + " --jitter sobol", &output), 1) << output;
  EXPECT_EQ(test::run_command(tool() + " " + scene + " --out " + dir.string() + " --shade-mip-bias -2x", &output), 1)
      << output;
  EXPECT_NE(output.find("--shade-mip-bias"), std::string::npos) << output;
  EXPECT_EQ(test::run_command(tool() + " " + scene + " --out " + dir.string() + " --frames 0-3 --duration 1", &output), 1)
      << output;
  // An output folder that cannot be created is an output error.
  std::ofstream(dir / "a_file") << "x";
  EXPECT_EQ(test::run_command(tool() + " " + scene + " --out " + (dir / "a_file" / "sub").string() + " --size 32x24", &output),
            4)
      << output;
}

TEST(RenderCli, WritesOnlyTheLayersAskedFor) {
  const auto dir = test::scratch_dir("render_cli_layers");
  const auto scene = write_test_scene(dir).string();
  const auto out = dir / "out";
  std::string output;
  ASSERT_EQ(test::run_command(tool() + " " + scene + " --out " + out.string() +
                                  " --size 64x48 --frames 0-1 --outputs gbuffer,shade --payload direct,ssao",
                              &output),
            0)
      << output;
  EXPECT_FALSE(fs::exists(out / "reference.0000.exr"));
  EXPECT_FALSE(fs::exists(out / "color.0000.exr"));
  auto g = read_exr_info((out / "gbuffer.0001.exr").string());
  ASSERT_TRUE(g) << g.error().message;
  std::vector<std::string> gc = g->channels;
  std::sort(gc.begin(), gc.end());
  EXPECT_EQ(gc, (std::vector<std::string>{"N.X", "N.Y", "N.Z", "albedo.B", "albedo.G", "albedo.R", "depth.Z", "id",
                                          "motion.X", "motion.Y", "prevDepth.Z"}));
  auto s = read_exr_info((out / "shade.0001.exr").string());
  ASSERT_TRUE(s) << s.error().message;
  std::vector<std::string> sc = s->channels;
  std::sort(sc.begin(), sc.end());
  EXPECT_EQ(sc, (std::vector<std::string>{"B", "G", "R", "direct.B", "direct.G", "direct.R", "ssao.Y"}));
  EXPECT_EQ(s->width, 16);
  EXPECT_EQ(s->height, 12);
  EXPECT_EQ(s->metadata.jitter_factor.value_or(0), 4);
  EXPECT_EQ(s->metadata.jitter_index.value_or(-1), 1);
  EXPECT_EQ(s->metadata.frame.value_or(-1), 1);
  EXPECT_NEAR(s->metadata.time.value_or(-1), 1.0 / 40.0, 1e-9);
  EXPECT_TRUE(s->metadata.world_to_ndc.has_value());
  EXPECT_TRUE(s->metadata.compute_ms.has_value());
  EXPECT_TRUE(s->metadata.timings_ms.count("shadeLow"));
  auto g0 = read_exr_info((out / "gbuffer.0000.exr").string());
  ASSERT_TRUE(g0);
  EXPECT_TRUE(g0->metadata.camera_cut.value_or(false));
  EXPECT_FALSE(g->metadata.camera_cut.value_or(true));
  EXPECT_NE(g0->metadata.tool.find("render-gbuffer"), std::string::npos);
  std::ifstream csv(out / "timings.csv");
  std::string header, line;
  std::getline(csv, header);
  EXPECT_EQ(header, "frame,time,gbuffer,lightMaps,shadeLow,shadeFull,reference,color");
  int rows = 0;
  while (std::getline(csv, line)) ++rows;
  EXPECT_EQ(rows, 2);
}

TEST(RenderCli, SameCommandTwiceGivesBitIdenticalPixels) {
  const auto dir = test::scratch_dir("render_cli_determinism");
  const auto scene = write_test_scene(dir).string();
  for (const char* run : {"a", "b"}) {
    std::string output;
    ASSERT_EQ(test::run_command(tool() + " " + scene + " --out " + (dir / run).string() +
                                    " --size 32x24 --frames 2-3 --reference-spp 2 --vpls 100 --shadow-map-size 256",
                                &output),
              0)
        << output;
  }
  for (const char* name : {"gbuffer", "shade", "reference", "color"}) {
    const std::string file = std::string(name) + ".0003.exr";
    auto a = read_exr((dir / "a" / file).string());
    auto b = read_exr((dir / "b" / file).string());
    ASSERT_TRUE(a && b) << file;
    ASSERT_EQ(a->channel_names(), b->channel_names());
    for (const auto& c : a->channel_names()) {
      const void* pa = a->channel_type(c) == ChannelType::UInt ? (const void*)a->uint_plane(c) : (const void*)a->plane(c);
      const void* pb = b->channel_type(c) == ChannelType::UInt ? (const void*)b->uint_plane(c) : (const void*)b->plane(c);
      EXPECT_EQ(std::memcmp(pa, pb, a->pixel_count() * 4), 0) << file << " " << c;
    }
  }
}

// True when every channel of the two files holds the same bits (float or uint), `skip` left out.
::testing::AssertionResult same_pixels(const fs::path& a_path, const fs::path& b_path,
                                       const std::vector<std::string>& skip = {}) {
  auto a = read_exr(a_path.string());
  auto b = read_exr(b_path.string());
  if (!a || !b) return ::testing::AssertionFailure() << "cannot read " << a_path << " or " << b_path;
  for (const auto& c : a->channel_names()) {
    if (std::find(skip.begin(), skip.end(), c) != skip.end()) continue;
    if (!b->has_channel(c)) return ::testing::AssertionFailure() << b_path << " has no " << c;
    const void* pa = a->channel_type(c) == ChannelType::UInt ? (const void*)a->uint_plane(c) : (const void*)a->plane(c);
    const void* pb = b->channel_type(c) == ChannelType::UInt ? (const void*)b->uint_plane(c) : (const void*)b->plane(c);
    if (std::memcmp(pa, pb, a->pixel_count() * 4) != 0)
      return ::testing::AssertionFailure() << a_path.filename() << " " << c << " differs";
  }
  return ::testing::AssertionSuccess();
}

// Issue 14: a sequence rendered as two shards (--frames 0-2, 3-5) gives exactly the files of one run (pixels and
// the camera-cut flag: only frame 0 starts the sequence).
TEST(RenderCli, ShardedRenderEqualsOneRun) {
  const auto dir = test::scratch_dir("render_cli_shards");
  const auto scene = write_test_scene(dir).string();
  const std::string common = tool() + " " + scene + " --size 32x24 --reference-spp 2 --vpls 64 --shadow-map-size 256";
  std::string out;
  ASSERT_EQ(test::run_command(common + " --frames 0-5 --out " + (dir / "one").string(), &out), 0) << out;
  ASSERT_EQ(test::run_command(common + " --frames 0-2 --out " + (dir / "two").string(), &out), 0) << out;
  ASSERT_EQ(test::run_command(common + " --frames 3-5 --out " + (dir / "two").string(), &out), 0) << out;
  for (const char* name : {"gbuffer", "shade", "reference", "color"})
    for (const char* f : {".0002.exr", ".0003.exr", ".0005.exr"}) {
      const std::string file = std::string(name) + f;
      EXPECT_TRUE(same_pixels(dir / "one" / file, dir / "two" / file)) << file;
      auto a = read_exr_info((dir / "one" / file).string());
      auto b = read_exr_info((dir / "two" / file).string());
      ASSERT_TRUE(a && b);
      EXPECT_EQ(a->metadata.camera_cut.value_or(false), b->metadata.camera_cut.value_or(false)) << file;
      EXPECT_FALSE(b->metadata.camera_cut.value_or(false)) << file;
    }
}

// Issue 16: noise patterns (SSAO, VPL sets, random jitter) are keyed by the instant, so a 40 Hz frame n and a
// 120 Hz frame 3n are the same render: every payload, the reference and the colour, and the G-buffer's geometry
// (its motion and prevDepth differ: they describe the previous frame of each rate).
TEST(RenderCli, FramesAtTheSameInstantRenderAlikeAtAnyRate) {
  const auto dir = test::scratch_dir("render_cli_instants");
  const auto scene = write_test_scene(dir).string();
  const std::string common = tool() + " " + scene + " --size 32x24 --reference-spp 3 --vpls 64 --shadow-map-size 256 " +
                             "--jitter random --shade-jitter random";
  std::string out;
  ASSERT_EQ(test::run_command(common + " --fps 40 --frames 0-2 --out " + (dir / "r40").string(), &out), 0) << out;
  ASSERT_EQ(test::run_command(common + " --fps 120 --frames 0-6 --out " + (dir / "r120").string(), &out), 0) << out;
  for (int n : {1, 2}) {
    char a[32], b[32];
    std::snprintf(a, sizeof a, ".%04d.exr", n);
    std::snprintf(b, sizeof b, ".%04d.exr", 3 * n);
    for (const char* name : {"shade", "reference", "color"})
      EXPECT_TRUE(same_pixels(dir / "r40" / (std::string(name) + a), dir / "r120" / (std::string(name) + b))) << name << n;
    EXPECT_TRUE(same_pixels(dir / "r40" / (std::string("gbuffer") + a), dir / "r120" / (std::string("gbuffer") + b),
                            {"motion.X", "motion.Y", "prevDepth.Z"}));
  }
}

// Issue 16: a payload without a radiance term (direct, gi) still has a sum: the visibility terms as grey.
TEST(RenderCli, PayloadWithoutRadianceHasANonZeroSum) {
  const auto dir = test::scratch_dir("render_cli_visibility_sum");
  const auto scene = write_test_scene(dir).string();
  std::string out;
  ASSERT_EQ(test::run_command(tool() + " " + scene + " --size 32x24 --factor 1 --frames 0-0 --outputs gbuffer,shade " +
                                  "--shade-jitter none --payload ssao --out " + (dir / "o").string(), &out), 0) << out;
  auto s = read_exr((dir / "o" / "shade.0000.exr").string());
  auto g = read_exr((dir / "o" / "gbuffer.0000.exr").string());
  ASSERT_TRUE(s && g);
  std::size_t surface = 0;
  for (std::size_t i = 0; i < s->pixel_count(); ++i) {
    const bool on_surface = g->uint_plane("id")[i] != 0;  // the background has no payload at all
    EXPECT_EQ(s->plane("R")[i], on_surface ? s->plane("ssao.Y")[i] : 0.0f) << i;
    EXPECT_EQ(s->plane("G")[i], s->plane("R")[i]);
    surface += on_surface && s->plane("R")[i] > 0.0f;
  }
  EXPECT_GT(surface, 50u);
}

// Issue 11: runaway ranges and malformed scenes are refused with a message; nothing is rendered.
TEST(RenderCli, RunawayRangesAndMalformedScenesAreRefused) {
  const auto dir = test::scratch_dir("render_cli_runaway");
  const auto scene = write_test_scene(dir).string();
  const std::string cmd = tool() + " " + scene + " --size 32x24 --out " + (dir / "o").string();
  std::string out;
  for (const char* bad : {"--frames 2147483647-2147483647", "--frames -1", "--duration inf", "--duration 1e30",
                          "--duration -1", "--fps nan", "--camera 99999999999999999999999",
                          "--clip 99999999999999999999999"}) {
    EXPECT_EQ(test::run_command(cmd + " " + bad, &out), 1) << bad << "\n" << out;
    EXPECT_LT(out.size(), 600u) << out;
    EXPECT_EQ(out.find("stoul"), std::string::npos) << out;
  }
  EXPECT_FALSE(fs::exists(dir / "o" / "gbuffer.0000.exr"));
  // Texture coordinates holding NaN, and a camera node scaled by zero: input errors, not NaN images.
  std::ifstream in(scene);
  std::string json((std::istreambuf_iterator<char>(in)), {});
  const float nan_uv[8] = {0, 0, NAN, 0, 1, 1, 0, 1};
  std::vector<unsigned char> uv(reinterpret_cast<const unsigned char*>(nan_uv),
                                reinterpret_cast<const unsigned char*>(nan_uv) + sizeof nan_uv);
  std::string with_uv = json;
  with_uv.replace(with_uv.find(R"("attributes": {"POSITION": 0})"), 29, R"("attributes": {"POSITION": 0, "TEXCOORD_0": 5})");
  with_uv.replace(with_uv.find(R"({"bufferView": 3, "componentType": 5126, "count": 2, "type": "VEC3"}])"), 69,
                  R"({"bufferView": 3, "componentType": 5126, "count": 2, "type": "VEC3"},
    {"bufferView": 4, "componentType": 5126, "count": 4, "type": "VEC2"}])");
  with_uv.replace(with_uv.find(R"({"buffer": 0, "byteOffset": 116, "byteLength": 24}])"), 51,
                  R"({"buffer": 0, "byteOffset": 116, "byteLength": 24},
    {"buffer": 1, "byteOffset": 0, "byteLength": 32}])");
  with_uv.replace(with_uv.rfind("]"), 1, R"(, {"byteLength": 32, "uri": "data:application/octet-stream;base64,)" +
                                             base64(uv) + R"("}])");
  std::ofstream(dir / "nan_uv.gltf") << with_uv;
  EXPECT_EQ(test::run_command(tool() + " " + (dir / "nan_uv.gltf").string() + " --size 32x24 --out " + (dir / "o").string(),
                              &out), 2) << out;
  EXPECT_NE(out.find("NaN"), std::string::npos) << out;
  std::string zero_camera = json;
  zero_camera.replace(zero_camera.find(R"("nodes": [{"mesh": 0}, {"mesh": 1}])"), 35,
                      R"("nodes": [{"mesh": 0}, {"mesh": 1}, {"camera": 0, "scale": [0, 0, 0], "translation": [0, 1, 5]}],
  "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1, "zfar": 100}}])");
  zero_camera.replace(zero_camera.find(R"("scenes": [{"nodes": [0, 1]}])"), 29, R"("scenes": [{"nodes": [0, 1, 2]}])");
  std::ofstream(dir / "zero_camera.gltf") << zero_camera;
  EXPECT_EQ(test::run_command(tool() + " " + (dir / "zero_camera.gltf").string() + " --size 32x24 --out " +
                                  (dir / "o").string(), &out), 2) << out;
  EXPECT_NE(out.find("camera's transform"), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(dir / "o" / "gbuffer.0000.exr"));
}

// Issue 26 item 14 and its exit-code cases: every float option has a finite range (said in --help) that keeps its
// arithmetic finite (--fps 1e-45 wrote temporal:time = inf), non-finite values are refused, and an empty value is a
// usage error naming the option (CLI11 read `--ssao-radius ""` as 0, a valid radius). Nothing is written.
TEST(RenderCli, FloatOptionsHaveFiniteRangesAndEmptyValuesAreRefused) {
  const auto dir = test::scratch_dir("render_cli_ranges");
  const auto scene = write_test_scene(dir).string();
  // No --frames: it excludes --duration (every case is refused before anything renders).
  const std::string cmd = tool() + " " + scene + " --size 32x24 --out " + (dir / "o").string();
  std::string out;
  const std::pair<const char*, const char*> cases[] = {
      {"--fps 1e-45", "--fps"}, {"--fps 20000", "--fps"}, {"--shadow-bias nan", "--shadow-bias"},
      {"--shadow-bias -inf", "--shadow-bias"}, {"--shadow-bias 1e30", "--shadow-bias"},
      {"--ssao-radius inf", "--ssao-radius"}, {"--ssao-radius -1", "--ssao-radius"},
      {"--camera-period 0", "--camera-period"}, {"--camera-period 1e300", "--camera-period"},
      {"--duration 1e300", "--duration"}, {"--key-light -1", "--key-light"}, {"--fill-light nan", "--fill-light"},
      {"--ambient inf", "--ambient"}, {"--ambient 1000", "--ambient"}, {"--lights sun", "--lights"},
      {"--ssao-radius=", "--ssao-radius"}, {"--ssao-radius ''", "--ssao-radius"}, {"--shadow-bias ''", "--shadow-bias"},
      {"--fps ''", "--fps"}, {"--seed ''", "--seed"}, {"--camera ''", "--camera"}, {"--key-light=", "--key-light"},
      {"--lights ''", "--lights"}, {"--size ''", "--size"}, {"--pcf ''", "--pcf"}};
  for (auto [bad, flag] : cases) {
    EXPECT_EQ(test::run_command(cmd + " " + bad, &out), 1) << bad << "\n" << out;
    EXPECT_NE(out.find(std::string("render-gbuffer: ") + flag), std::string::npos) << bad << "\n" << out;
  }
  EXPECT_FALSE(fs::exists(dir / "o" / "color.0000.exr"));
  // --help gives each float option its range: the option's line (or the next, after CLI11's "Excludes") has one.
  ASSERT_EQ(test::run_command(tool() + " --help", &out), 0) << out;
  std::istringstream help(out);
  std::vector<std::string> lines;
  for (std::string line; std::getline(help, line);) lines.push_back(line);
  int floats = 0;
  for (std::size_t i = 0; i + 1 < lines.size(); ++i) {
    if (lines[i].find(" FLOAT") == std::string::npos) continue;
    ++floats;
    const std::string text = lines[i] + lines[i + 1];
    EXPECT_NE(text.find("(["), std::string::npos) << lines[i];
  }
  EXPECT_GE(floats, 9);
  for (const char* range : {"--fps FLOAT=40", "[0.001, 10000]", "[-64, 64]", "[0, 1000000]", "--key-light", "--fill-light",
                            "--ambient", "--lights"})
    EXPECT_NE(out.find(range), std::string::npos) << range;
}

// Issue 25 item 4: a frame whose covered pixels are mostly below 1 % of its maximum is warned about (once, naming the
// frame and the options that light it); the automatic lighting of the same scene gives no warning.
TEST(RenderCli, DarkFramesAreWarnedAbout) {
  const auto dir = test::scratch_dir("render_cli_dark");
  const auto scene = write_test_scene(dir).string();
  const std::string cmd = tool() + " " + scene + " --size 32x24 --frames 0-2 --outputs color --out " + (dir / "o").string();
  std::string out;
  ASSERT_EQ(test::run_command(cmd + " --key-light 0 --fill-light 0 --ambient 0", &out), 0) << out;
  const std::string warning = "render-gbuffer: warning: frame 0: 100 % of the covered pixels are below 1 % of the "
                              "frame's maximum: the render is mostly black";
  EXPECT_NE(out.find(warning), std::string::npos) << out;
  EXPECT_NE(out.find("--lights auto"), std::string::npos) << out;
  EXPECT_EQ(out.find("warning", out.find(warning) + warning.size()), std::string::npos) << "warned more than once\n" << out;
  ASSERT_EQ(test::run_command(cmd, &out), 0) << out;
  EXPECT_EQ(out.find("warning"), std::string::npos) << out;
}

// Issue 22: the EGL path. On this machine EGL's only device is Mesa's software one (llvmpipe, as OSMesa), so
// `--gl egl` must write exactly the files of `--gl osmesa` (every plane of the four outputs), and each header names
// the context and renderer that made it.
TEST(RenderCli, EglAndOsmesaWriteBitIdenticalFiles) {
  const auto dir = test::scratch_dir("render_cli_egl");
  const std::string scene = (test::source_dir() / "assets" / "scenes" / "tower.glb").string();
  const std::string common = tool() + " " + scene + " --size 64x48 --frames 0-2 --reference-spp 2 --vpls 64 " +
                             "--shadow-map-size 256";
  std::string out;
  ASSERT_EQ(test::run_command(common + " --gl osmesa --out " + (dir / "osmesa").string(), &out), 0) << out;
  ASSERT_EQ(test::run_command(common + " --gl egl --out " + (dir / "egl").string(), &out), 0) << out;
  for (const char* name : {"gbuffer", "shade", "reference", "color"})
    for (const char* f : {".0000.exr", ".0001.exr", ".0002.exr"}) {
      const std::string file = std::string(name) + f;
      EXPECT_TRUE(same_pixels(dir / "osmesa" / file, dir / "egl" / file)) << file;
      auto a = read_exr_info((dir / "osmesa" / file).string());
      auto b = read_exr_info((dir / "egl" / file).string());
      ASSERT_TRUE(a && b) << file;
      EXPECT_EQ(a->metadata.extra["glContext"], "osmesa") << file;
      EXPECT_EQ(b->metadata.extra["glContext"], "egl") << file;
      EXPECT_EQ(b->metadata.extra["glDevice"], "0") << file;
      EXPECT_EQ(a->metadata.extra["glRenderer"].rfind("llvmpipe", 0), 0u) << a->metadata.extra["glRenderer"];
      EXPECT_EQ(a->metadata.extra["glRenderer"], b->metadata.extra["glRenderer"]);
      EXPECT_NE(b->metadata.extra["glVersion"].find("4.5"), std::string::npos) << b->metadata.extra["glVersion"];
      EXPECT_FALSE(b->metadata.extra["glVendor"].empty());
    }
}

TEST(RenderCli, ListGlDevicesListsTheSoftwareDevice) {
  std::string out;
  // No scene and no --out: listing needs neither.
  ASSERT_EQ(test::run_command(tool() + " --list-gl-devices", &out), 0) << out;
  bool found = false;
  std::istringstream lines(out);
  for (std::string line; std::getline(lines, line);)
    found = found || (line.find("\tsoftware\tllvmpipe") != std::string::npos &&
                      line.find("EGL_MESA_device_software") != std::string::npos);
  EXPECT_TRUE(found) << out;
}

TEST(RenderCli, GlOptionsAreCheckedAndAutoTakesOsmesaWithoutAGpu) {
  const auto dir = test::scratch_dir("render_cli_gl_options");
  const auto scene = write_test_scene(dir).string();
  const std::string cmd = tool() + " " + scene + " --size 32x24 --frames 0-0 --outputs gbuffer";
  std::string out;
  EXPECT_EQ(test::run_command(cmd + " --gl vulkan --out " + (dir / "o").string(), &out), 1) << out;
  EXPECT_EQ(test::run_command(cmd + " --gl egl --gl-device 99 --out " + (dir / "o").string(), &out), 1) << out;
  EXPECT_NE(out.find("--gl-device"), std::string::npos) << out;
  EXPECT_EQ(test::run_command(cmd + " --gl-device -2 --out " + (dir / "o").string(), &out), 1) << out;
  EXPECT_FALSE(fs::exists(dir / "o" / "gbuffer.0000.exr"));
  // auto: a hardware EGL device when --list-gl-devices shows one, else OSMesa.
  std::string list;
  ASSERT_EQ(test::run_command(tool() + " --list-gl-devices", &list), 0) << list;
  const bool gpu = list.find("\thardware\t") != std::string::npos;
  ASSERT_EQ(test::run_command(cmd + " --gl auto --out " + (dir / "auto").string(), &out), 0) << out;
  auto info = read_exr_info((dir / "auto" / "gbuffer.0000.exr").string());
  ASSERT_TRUE(info) << info.error().message;
  EXPECT_EQ(info->metadata.extra["glContext"], gpu ? "egl" : "osmesa") << list;
  // The default is OSMesa (the CI path).
  ASSERT_EQ(test::run_command(cmd + " --out " + (dir / "default").string(), &out), 0) << out;
  info = read_exr_info((dir / "default" / "gbuffer.0000.exr").string());
  ASSERT_TRUE(info) << info.error().message;
  EXPECT_EQ(info->metadata.extra["glContext"], "osmesa");
}

}  // namespace
}  // namespace temporal
