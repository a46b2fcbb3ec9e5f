// render-gbuffer against hostile scenes and output folders (issue 26, items 3, 4, 8, 9, 10, 15): outputs never
// replace the scene's own files, shards keep each other's timings, runaway reference sample counts, JSON nested
// deep enough to overflow the stack, inputs that cannot be examined, and degenerate cameras, rotations, normals
// and texture coordinates. Each case checks the exit code, that the message names the file (and element), and
// that nothing was rendered or replaced.
#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace temporal {
namespace {

namespace fs = std::filesystem;

std::string tool() { return test::tool_path("render-gbuffer").string(); }

using test::read_file;
using test::base64;

std::vector<unsigned char> bytes_of(const std::vector<float>& f) {
  const auto* p = reinterpret_cast<const unsigned char*>(f.data());
  return std::vector<unsigned char>(p, p + f.size() * sizeof(float));
}

// One quad (two triangles) with POSITION in buffer 0 and, when given, NORMAL (accessor 1) and TEXCOORD_0
// (accessor 2 when there are normals, else 1) in the same buffer; NODES and CAMERAS are spliced in as JSON.
// The buffer is a data: URI unless `buffer_file` is given (then it is written there and named by a relative uri).
struct QuadScene {
  std::vector<float> normals, texcoords;
  std::string nodes = R"({"mesh": 0})";
  std::string scene_nodes = "[0]";
  std::string cameras;   // e.g. R"("cameras": [...],)"
  std::string extras;    // e.g. R"("extras": [[1]],)"
  std::string buffer_uri;  // relative file name of the buffer; empty: a data: URI
};

std::string quad_json(const QuadScene& q, const fs::path& dir) {
  const std::vector<float> pos = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, -1, 0, 1, 1, 0, -1, 1, 0};
  std::vector<float> all = pos;
  all.insert(all.end(), q.normals.begin(), q.normals.end());
  all.insert(all.end(), q.texcoords.begin(), q.texcoords.end());
  const std::vector<unsigned char> buf = bytes_of(all);
  std::string attributes = R"("POSITION": 0)", accessors =
      R"({"bufferView": 0, "componentType": 5126, "count": 6, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]})";
  std::string views = R"({"buffer": 0, "byteOffset": 0, "byteLength": 72})";
  std::size_t offset = 72;
  int index = 1;
  if (!q.normals.empty()) {
    attributes += R"(, "NORMAL": )" + std::to_string(index++);
    accessors += R"(, {"bufferView": 1, "componentType": 5126, "count": 6, "type": "VEC3"})";
    views += R"(, {"buffer": 0, "byteOffset": 72, "byteLength": 72})";
    offset += 72;
  }
  if (!q.texcoords.empty()) {
    const int view = q.normals.empty() ? 1 : 2;
    attributes += R"(, "TEXCOORD_0": )" + std::to_string(index++);
    accessors += R"(, {"bufferView": )" + std::to_string(view) + R"(, "componentType": 5126, "count": 6, "type": "VEC2"})";
    views += R"(, {"buffer": 0, "byteOffset": )" + std::to_string(offset) + R"(, "byteLength": 48})";
  }
  std::string uri;
  if (q.buffer_uri.empty()) {
    uri = "data:application/octet-stream;base64," + base64(buf);
  } else {
    std::ofstream(dir / q.buffer_uri, std::ios::binary).write(reinterpret_cast<const char*>(buf.data()), std::streamsize(buf.size()));
    uri = q.buffer_uri;
  }
  return R"({"asset": {"version": "2.0"}, )" + q.extras + q.cameras + R"( "scene": 0, "scenes": [{"nodes": )" +
         q.scene_nodes + R"(}], "nodes": [)" + q.nodes + R"(], "meshes": [{"primitives": [{"attributes": {)" +
         attributes + R"(}}]}], "accessors": [)" + accessors + R"(], "bufferViews": [)" + views + R"(], "buffers": [)" +
         R"({"byteLength": )" + std::to_string(buf.size()) + R"(, "uri": ")" + uri + R"("}]})";
}

fs::path write_quad(const fs::path& dir, const std::string& name, const QuadScene& q) {
  const fs::path path = dir / name;
  std::ofstream(path) << quad_json(q, dir);
  return path;
}

// A quad whose camera node (node 1) carries `camera_node` fields and whose camera is `camera`.
QuadScene with_camera(const std::string& camera_node, const std::string& camera) {
  QuadScene q;
  q.nodes = R"({"mesh": 0}, {"camera": 0, )" + camera_node + "}";
  q.scene_nodes = "[0, 1]";
  q.cameras = R"("cameras": [{"type": "perspective", "perspective": )" + camera + "}],";
  return q;
}

int render(const fs::path& scene, const fs::path& out, const std::string& extra, std::string* output) {
  return test::run_command(tool() + " " + scene.string() + " --out " + out.string() + " --size 32x24 --reference-spp 1 " +
                               "--vpls 16 --shadow-map-size 64 " + extra,
                           output);
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// The frame numbers of timings.csv's rows (the header excluded), in file order.
std::vector<int> timing_frames(const fs::path& csv) {
  std::ifstream in(csv);
  std::string line;
  std::vector<int> frames;
  std::getline(in, line);
  while (std::getline(in, line)) frames.push_back(std::stoi(line.substr(0, line.find(','))));
  return frames;
}

// Item 3: a scene file named timings.csv inside --out, and a glTF buffer and a USD texture named like the frames
// render-gbuffer writes (color.0000.exr) inside --out: refused with exit 1 naming both paths; the inputs are intact.
TEST(RenderHostile, OutputsNeverReplaceTheScenesInputs) {
  const auto dir = test::scratch_dir("render_hostile_inputs");
  std::string out;
  // The scene file itself is DIR/out/timings.csv.
  fs::create_directories(dir / "out");
  const fs::path scene = write_quad(dir / "out", "timings.csv", QuadScene{});
  const std::string before = read_file(scene);
  EXPECT_EQ(render(scene, dir / "out", "--frames 0-0", &out), 1) << out;
  EXPECT_TRUE(contains(out, "timings.csv")) << out;
  EXPECT_TRUE(contains(out, "is the scene's input")) << out;
  EXPECT_EQ(read_file(scene), before);
  EXPECT_FALSE(fs::exists(dir / "out" / "gbuffer.0000.exr"));

  // The glTF's buffer is DIR/b/color.0000.exr; rendering frame 0 into DIR/b would replace it, frame 1 would not.
  fs::create_directories(dir / "b");
  QuadScene q;
  q.buffer_uri = "b/color.0000.exr";
  const fs::path buffered = write_quad(dir, "buffered.gltf", q);
  const std::string buffer = read_file(dir / "b" / "color.0000.exr");
  EXPECT_EQ(render(buffered, dir / "b", "--frames 0-1", &out), 1) << out;
  EXPECT_TRUE(contains(out, (dir / "b" / "color.0000.exr").string())) << out;
  EXPECT_TRUE(contains(out, "is the scene's input")) << out;
  EXPECT_EQ(read_file(dir / "b" / "color.0000.exr"), buffer);
  EXPECT_EQ(render(buffered, dir / "b", "--frames 1-1", &out), 0) << out;
  EXPECT_EQ(read_file(dir / "b" / "color.0000.exr"), buffer);

  // A USD scene whose texture (a PNM image, read by content) is DIR/u/color.0000.exr.
  fs::create_directories(dir / "u");
  {
    std::ofstream tex(dir / "u" / "color.0000.exr", std::ios::binary);
    tex << "P6\n2 2\n255\n";
    for (int i = 0; i < 12; ++i) tex.put(char(i * 20));
  }
  const std::string texture = read_file(dir / "u" / "color.0000.exr");
  std::ofstream(dir / "textured.usda") << R"(#usda 1.0
def Scope "Looks" {
 def Material "M" {
  token outputs:surface.connect = </Looks/M/S.outputs:surface>
  def Shader "S" {
   uniform token info:id = "UsdPreviewSurface"
   color3f inputs:diffuseColor.connect = </Looks/M/T.outputs:rgb>
   token outputs:surface
  }
  def Shader "T" {
   uniform token info:id = "UsdUVTexture"
   asset inputs:file = @u/color.0000.exr@
   float3 outputs:rgb
  }
 }
}
def Mesh "Quad" {
 rel material:binding = </Looks/M>
 point3f[] points = [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)]
 int[] faceVertexCounts = [4]
 int[] faceVertexIndices = [0, 1, 2, 3]
 texCoord2f[] primvars:st = [(0, 0), (1, 0), (1, 1), (0, 1)] (
  interpolation = "vertex"
 )
}
)";
  EXPECT_EQ(render(dir / "textured.usda", dir / "u", "--frames 0-0 --outputs color", &out), 1) << out;
  EXPECT_TRUE(contains(out, "u/color.0000.exr")) << out;
  EXPECT_TRUE(contains(out, "is the scene's input")) << out;
  EXPECT_EQ(read_file(dir / "u" / "color.0000.exr"), texture);
  // The same scene renders into another folder (the texture is read, not refused).
  EXPECT_EQ(render(dir / "textured.usda", dir / "v", "--frames 0-0 --outputs color", &out), 0) << out;
}

// Item 4: shards of one sequence (same --out, frames 0-1 and 2-3, as the Snakefile's render_chunk), one after the
// other and at the same time, leave one row per frame; a re-render replaces its frames' rows; a timings.csv that
// is not one is refused (exit 4) and kept.
TEST(RenderHostile, ShardsKeepEachOthersTimings) {
  const auto dir = test::scratch_dir("render_hostile_timings");
  QuadScene q;
  const fs::path scene = write_quad(dir, "quad.gltf", q);
  std::string out;
  ASSERT_EQ(render(scene, dir / "seq", "--frames 0-1 --outputs gbuffer", &out), 0) << out;
  ASSERT_EQ(render(scene, dir / "seq", "--frames 2-3 --outputs gbuffer", &out), 0) << out;
  EXPECT_EQ(timing_frames(dir / "seq" / "timings.csv"), (std::vector<int>{0, 1, 2, 3}));
  const std::string header = read_file(dir / "seq" / "timings.csv").substr(0, read_file(dir / "seq" / "timings.csv").find('\n'));
  EXPECT_EQ(header, "frame,time,gbuffer,lightMaps,shadeLow,shadeFull,reference,color");
  // Re-rendering frames 1-2 with the colour instead: their rows are replaced (the colour column is filled).
  ASSERT_EQ(render(scene, dir / "seq", "--frames 1-2 --outputs color", &out), 0) << out;
  EXPECT_EQ(timing_frames(dir / "seq" / "timings.csv"), (std::vector<int>{0, 1, 2, 3}));
  {
    std::ifstream in(dir / "seq" / "timings.csv");
    std::string line;
    std::getline(in, line);
    for (int f = 0; f < 4; ++f) {
      ASSERT_TRUE(std::getline(in, line));
      const bool colour = line.back() != ',';  // the last column (color) is empty when the pass did not run
      EXPECT_EQ(colour, f == 1 || f == 2) << line;
    }
  }
  // Two shards at the same time (each merges after every frame): every frame's row survives.
  const std::string common = tool() + " " + scene.string() + " --out " + (dir / "par").string() +
                             " --size 32x24 --outputs gbuffer --frames ";
  ASSERT_EQ(test::run_command(common + "0-11 & a=$!; " + common + "12-23 & b=$!; wait $a && wait $b", &out), 0) << out;
  std::vector<int> all(24);
  for (int f = 0; f < 24; ++f) all[std::size_t(f)] = f;
  EXPECT_EQ(timing_frames(dir / "par" / "timings.csv"), all);
  // A file that is not a timings file: exit 4, kept as it was.
  fs::create_directories(dir / "foreign");
  std::ofstream(dir / "foreign" / "timings.csv") << "my,own,table\n1,2,3\n";
  EXPECT_EQ(render(scene, dir / "foreign", "--frames 0-0", &out), 4) << out;
  EXPECT_TRUE(contains(out, "timings.csv")) << out;
  EXPECT_EQ(read_file(dir / "foreign" / "timings.csv"), "my,own,table\n1,2,3\n");
  EXPECT_FALSE(fs::exists(dir / "foreign" / "gbuffer.0000.exr"));
}

// Item 8: --reference-spp is bounded (kMaxReferenceSpp = 4096): beyond, exit 1 naming the option, nothing rendered.
TEST(RenderHostile, ReferenceSamplesAreBounded) {
  const auto dir = test::scratch_dir("render_hostile_spp");
  const fs::path scene = write_quad(dir, "quad.gltf", QuadScene{});
  std::string out;
  for (const char* spp : {"1000000", "4097", "2147483647"}) {
    EXPECT_EQ(test::run_command(tool() + " " + scene.string() + " --out " + (dir / "o").string() +
                                    " --size 32x24 --frames 0-0 --reference-spp " + spp,
                                &out),
              1)
        << spp << "\n" << out;
    EXPECT_TRUE(contains(out, "--reference-spp")) << out;
    EXPECT_TRUE(contains(out, "4096")) << out;
  }
  EXPECT_FALSE(fs::exists(dir / "o"));
  EXPECT_EQ(test::run_command(tool() + " --help", &out), 0);
  EXPECT_TRUE(contains(out, "--reference-spp")) << out;
}

// Item 9: 20 000 nested arrays in `extras` (the stack overflowed in the JSON conversion, exit 139) are refused
// before parsing with exit 2 naming the file; nesting at the limit (256) still loads, in .gltf and .glb.
TEST(RenderHostile, DeeplyNestedJsonIsAnInputError) {
  const auto dir = test::scratch_dir("render_hostile_json");
  auto nested = [](int depth) { return R"("extras": )" + std::string(std::size_t(depth), '[') + std::string(std::size_t(depth), ']') + ","; };
  QuadScene deep;
  deep.extras = nested(20000);
  const fs::path bad = write_quad(dir, "deep.gltf", deep);
  std::string out;
  EXPECT_EQ(render(bad, dir / "o", "--frames 0-0", &out), 2) << out.substr(0, 2000);
  EXPECT_TRUE(contains(out, "deep.gltf")) << out.substr(0, 2000);
  EXPECT_TRUE(contains(out, "nests")) << out.substr(0, 2000);
  EXPECT_FALSE(fs::exists(dir / "o" / "gbuffer.0000.exr"));
  // The same JSON in a .glb container (JSON chunk only).
  {
    std::string json = quad_json(deep, dir);
    while (json.size() % 4) json += ' ';
    std::string glb = "glTF";
    auto u32 = [&](std::uint32_t v) {
      for (int i = 0; i < 4; ++i) glb += char((v >> (8 * i)) & 0xff);
    };
    u32(2);
    u32(std::uint32_t(12 + 8 + json.size()));
    u32(std::uint32_t(json.size()));
    u32(0x4E4F534Au);
    glb += json;
    std::ofstream(dir / "deep.glb", std::ios::binary) << glb;
  }
  EXPECT_EQ(render(dir / "deep.glb", dir / "o", "--frames 0-0", &out), 2) << out.substr(0, 2000);
  EXPECT_TRUE(contains(out, "deep.glb")) << out.substr(0, 2000);
  // 256 levels in all (the document's object is one of them) still load; brackets inside strings do not count.
  QuadScene fine;
  fine.extras = nested(250) + R"( "x": "[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[\"",)";
  EXPECT_EQ(render(write_quad(dir, "fine.gltf", fine), dir / "f", "--frames 0-0 --outputs gbuffer", &out), 0) << out;
}

// Item 10: an input that cannot be examined (a symbolic link loop) is an input error (exit 2) naming it, not
// exit 5 with a filesystem exception.
TEST(RenderHostile, InputsThatCannotBeExaminedAreInputErrors) {
  const auto dir = test::scratch_dir("render_hostile_loop");
  fs::create_symlink("loop.gltf", dir / "loop.gltf");
  std::string out;
  EXPECT_EQ(render(dir / "loop.gltf", dir / "o", "--frames 0-0", &out), 2) << out;
  EXPECT_TRUE(contains(out, "loop.gltf")) << out;
  EXPECT_TRUE(contains(out, "symbolic links")) << out;
  EXPECT_FALSE(contains(out, "please report")) << out;
  // A buffer that is a link loop.
  QuadScene q;
  q.buffer_uri = "buffer.bin";
  const fs::path scene = write_quad(dir, "quad.gltf", q);
  fs::remove(dir / "buffer.bin");
  fs::create_symlink("buffer.bin", dir / "buffer.bin");
  EXPECT_EQ(render(scene, dir / "o", "--frames 0-0", &out), 2) << out;
  EXPECT_TRUE(contains(out, "quad.gltf")) << out;
  EXPECT_FALSE(contains(out, "please report")) << out;
  // An output folder that is a link loop is an output error.
  fs::create_symlink("outloop", dir / "outloop");
  EXPECT_EQ(render(write_quad(dir, "plain.gltf", QuadScene{}), dir / "outloop", "--frames 0-0", &out), 4) << out;
  EXPECT_FALSE(contains(out, "please report")) << out;
}

// Item 15: degenerate cameras and vertex data: exit 2 naming the file and the element, nothing rendered.
TEST(RenderHostile, DegenerateCamerasRotationsNormalsAndTexcoordsAreInputErrors) {
  const auto dir = test::scratch_dir("render_hostile_degenerate");
  std::string out;
  auto refused = [&](const fs::path& scene, const std::vector<std::string>& parts) {
    EXPECT_EQ(render(scene, dir / "o", "--frames 0-1", &out), 2) << scene << "\n" << out;
    EXPECT_TRUE(contains(out, scene.filename().string())) << out;
    for (const std::string& p : parts) EXPECT_TRUE(contains(out, p)) << p << "\n" << out;
    EXPECT_FALSE(fs::exists(dir / "o" / "gbuffer.0000.exr")) << scene;
  };
  const std::string ok_camera = R"({"yfov": 0.8, "znear": 0.1, "zfar": 100})";
  // The control: the same camera with sane values renders.
  ASSERT_EQ(render(write_quad(dir, "ok.gltf", with_camera(R"("translation": [0, 0, 5])", ok_camera)), dir / "ok",
                   "--frames 0-0 --outputs gbuffer", &out), 0) << out;
  refused(write_quad(dir, "yfov.gltf", with_camera(R"("translation": [0, 0, 5])", R"({"yfov": 1e-45, "znear": 0.1, "zfar": 100})")),
          {"camera #0", "yfov (1e-45"});
  refused(write_quad(dir, "aspect.gltf", with_camera(R"("translation": [0, 0, 5])",
                                                      R"({"yfov": 0.8, "aspectRatio": 1e-45, "znear": 0.1, "zfar": 100})")),
          {"camera #0", "aspectRatio"});
  refused(write_quad(dir, "rotation.gltf", with_camera(R"("translation": [0, 0, 5], "rotation": [0, 0, 0, 0])", ok_camera)),
          {"node #1", "rotation"});
  refused(write_quad(dir, "huge.gltf", with_camera(R"("translation": [0, 0, 1e300])", ok_camera)), {"node #1", "not finite"});
  // A camera node whose matrix has an all-zero rotation part (the camera's transform is singular).
  refused(write_quad(dir, "matrix.gltf", with_camera(R"("matrix": [0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 5, 1])", ok_camera)),
          {"camera '0'", "not finite"});
  {
    // A rotation channel whose keys are zero quaternions.
    QuadScene q = with_camera(R"("translation": [0, 0, 5])", ok_camera);
    std::string json = quad_json(q, dir);
    const std::string anim = R"(, "animations": [{"channels": [{"sampler": 0, "target": {"node": 1, "path": "rotation"}}],
      "samplers": [{"input": 1, "output": 2}]}], "accessors": [)";
    json.replace(json.find(R"(, "accessors": [)"), 16, anim);
    json.replace(json.find(R"(], "bufferViews": [)"), 19,
                 R"(, {"bufferView": 1, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0], "max": [1]},
      {"bufferView": 2, "componentType": 5126, "count": 2, "type": "VEC4"}], "bufferViews": [)");
    json.replace(json.find(R"(], "buffers": [)"), 15, R"(, {"buffer": 1, "byteLength": 8}, {"buffer": 1, "byteOffset": 8, "byteLength": 32}], "buffers": [)");
    const std::vector<float> data = {0, 1, 0, 0, 0, 1, 0, 0, 0, 0};  // times 0, 1; key 0 the identity, key 1 zero
    json.replace(json.rfind("]"), 1, R"(, {"byteLength": 40, "uri": "data:application/octet-stream;base64,)" +
                                         base64(bytes_of(data)) + R"("}])");
    std::ofstream(dir / "zero_key.gltf") << json;
    refused(dir / "zero_key.gltf", {"rotation quaternion of length 0", "accessor 2"});
  }
  QuadScene normals;
  normals.normals = {0, 0, 1, 0, 0, 1, NAN, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
  refused(write_quad(dir, "nan_normals.gltf", normals), {"NORMAL", "accessor 1"});
  QuadScene huge_uv;
  huge_uv.texcoords = {0, 0, 1, 0, 3e38f, 1, 0, 0, 1, 1, 0, 1};
  refused(write_quad(dir, "huge_uv.gltf", huge_uv), {"TEXCOORD_0", "accessor 1"});

  // USD: a camera whose orient is (0, 0, 0, 0), a field of view under 1e-4 rad, a prim that references itself.
  const std::string quad = R"(def Mesh "Quad" {
 point3f[] points = [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)]
 int[] faceVertexCounts = [4]
 int[] faceVertexIndices = [0, 1, 2, 3]
}
)";
  std::ofstream(dir / "orient.usda") << "#usda 1.0\n" + quad + R"(def Camera "Cam" {
 double3 xformOp:translate = (0, 0, 5)
 quatf xformOp:orient = (0, 0, 0, 0)
 uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:orient"]
}
)";
  refused(dir / "orient.usda", {"/Cam", "length 0"});
  // The same as time samples (a key of length 0), and as an all-zero xformOp:transform rotation.
  std::ofstream(dir / "orient_keys.usda") << "#usda 1.0\n" + quad + R"(def Camera "Cam" {
 double3 xformOp:translate = (0, 0, 5)
 quatf xformOp:orient.timeSamples = { 0: (1, 0, 0, 0), 1: (0, 0, 0, 0) }
 uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:orient"]
}
)";
  refused(dir / "orient_keys.usda", {"/Cam", "length 0"});
  std::ofstream(dir / "matrix.usda") << "#usda 1.0\n" + quad + R"(def Camera "Cam" {
 matrix4d xformOp:transform = ( (0, 0, 0, 0), (0, 0, 0, 0), (0, 0, 0, 0), (0, 0, 5, 1) )
 uniform token[] xformOpOrder = ["xformOp:transform"]
}
)";
  refused(dir / "matrix.usda", {"camera 'Cam'", "not finite"});
  std::ofstream(dir / "narrow.usda") << "#usda 1.0\n" + quad + R"(def Camera "Cam" {
 float focalLength = 1e30
 double3 xformOp:translate = (0, 0, 5)
 uniform token[] xformOpOrder = ["xformOp:translate"]
}
)";
  refused(dir / "narrow.usda", {"/Cam", "field of view"});
  std::ofstream(dir / "self.usda") << "#usda 1.0\n" + quad + R"(def Xform "A" (
 references = </A>
) {
}
)";
  refused(dir / "self.usda", {"</A>", "cycle"});
  std::ofstream(dir / "ancestor.usda") << "#usda 1.0\n" + quad + R"(def Xform "A" {
 def Xform "B" (
  references = </A>
 ) {
 }
}
)";
  refused(dir / "ancestor.usda", {"</A>", "cycle"});
}

}  // namespace
}  // namespace temporal
