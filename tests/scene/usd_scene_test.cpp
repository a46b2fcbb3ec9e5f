// Text USD scenes through Scene::load and Scene::evaluate, on hand-written layers with hand-computed
// expectations: transform op stacks and their orders, time samples and the time-code mapping, quaternion
// slerp, mesh triangulation, primvar interpolations and the st flip, cameras, UsdLux conversion,
// UsdPreviewSurface materials and UsdUVTexture images, UsdSkel skinning and blend shapes, purpose /
// visibility / activation, upAxis, and every refusal (crate files, --clip, malformed scenes).
#include "test_support.h"

#include "temporal/scene/scene.h"

#include <OpenImageIO/imageio.h>
#include <glm/gtc/constants.hpp>
#include <glm/trigonometric.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

namespace temporal {
namespace {

namespace fs = std::filesystem;
constexpr float kEps = 1e-5f;

class UsdScene : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::scratch_dir(std::string("usd_scene_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  std::string write(const std::string& name, const std::string& body) {
    const fs::path p = dir_ / name;
    std::ofstream(p) << "#usda 1.0\n" << body;
    return p.string();
  }
  Scene load(const std::string& body, SceneLoadOptions options = {}) {
    auto s = Scene::load(write("scene.usda", body), options);
    EXPECT_TRUE(s) << (s ? "" : s.error().file + ": " + s.error().message);
    return s ? std::move(*s) : Scene();
  }
  fs::path dir_;
};

// A one-triangle mesh with the given extra lines, inside the given prim text.
std::string triangle(const std::string& name = "Tri", const std::string& extra = "") {
  return "def Mesh \"" + name + "\" {\n int[] faceVertexCounts = [3]\n int[] faceVertexIndices = [0, 1, 2]\n"
         " point3f[] points = [(1, 0, 0), (0, 1, 0), (0, 0, 1)]\n uniform token subdivisionScheme = \"none\"\n" + extra + "}\n";
}

glm::vec3 apply(const glm::mat4& m, glm::vec3 p) { return glm::vec3(m * glm::vec4(p, 1.0f)); }

void expect_vec3(glm::vec3 a, glm::vec3 b, float eps, const std::string& what) {
  EXPECT_NEAR(a.x, b.x, eps) << what;
  EXPECT_NEAR(a.y, b.y, eps) << what;
  EXPECT_NEAR(a.z, b.z, eps) << what;
}

TEST_F(UsdScene, TransformOpStacksInEveryOrder) {
  Scene s = load(R"(def Xform "TRS" {
 double3 xformOp:translate = (1, 2, 3)
 float3 xformOp:rotateXYZ = (90, 0, 0)
 float3 xformOp:scale = (2, 2, 2)
 uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:rotateXYZ", "xformOp:scale"]
)" + triangle("A") + R"(}
def Xform "XYZ" {
 float3 xformOp:rotateXYZ = (0, 90, 90)
 uniform token[] xformOpOrder = ["xformOp:rotateXYZ"]
)" + triangle("B") + R"(}
def Xform "ZYX" {
 float3 xformOp:rotateZYX = (0, 90, 90)
 uniform token[] xformOpOrder = ["xformOp:rotateZYX"]
)" + triangle("C") + R"(}
def Xform "Inverse" {
 double3 xformOp:translate = (4, 0, 0)
 uniform token[] xformOpOrder = ["xformOp:translate", "!invert!xformOp:translate"]
)" + triangle("D") + R"(}
def Xform "Parent" {
 double3 xformOp:translate = (10, 0, 0)
 uniform token[] xformOpOrder = ["xformOp:translate"]
 def Xform "Reset" {
  double3 xformOp:translate = (1, 0, 0)
  uniform token[] xformOpOrder = ["!resetXformStack!", "xformOp:translate"]
)" + triangle("E") + R"( }
}
def Xform "Matrix" {
 matrix4d xformOp:transform:a = ( (0, 1, 0, 0), (-1, 0, 0, 0), (0, 0, 1, 0), (4, 5, 6, 1) )
 quatf xformOp:orient = (0.70710678, 0, 0.70710678, 0)
 uniform token[] xformOpOrder = ["xformOp:transform:a", "xformOp:orient"]
)" + triangle("F") + "}\n");
  const FrameState f = s.evaluate(0.0);
  ASSERT_EQ(f.instances.size(), 6u);
  // T * Rx(90) * S: (1,0,0) -> (2,0,0) -> (2,0,0) -> (3,2,3); (0,1,0) -> (0,2,0) -> (0,0,2) -> (1,2,5).
  expect_vec3(apply(f.instances[0].model, {1, 0, 0}), {3, 2, 3}, kEps, "TRS x");
  expect_vec3(apply(f.instances[0].model, {0, 1, 0}), {1, 2, 5}, kEps, "TRS y");
  // rotateXYZ turns about X first, then Y, then Z: (1,0,0) -Ry90-> (0,0,-1) -Rz90-> (0,0,-1).
  expect_vec3(apply(f.instances[1].model, {1, 0, 0}), {0, 0, -1}, kEps, "rotateXYZ");
  // rotateZYX turns about Z first: (1,0,0) -Rz90-> (0,1,0) -Ry90-> (0,1,0).
  expect_vec3(apply(f.instances[2].model, {1, 0, 0}), {0, 1, 0}, kEps, "rotateZYX");
  expect_vec3(apply(f.instances[3].model, {1, 0, 0}), {1, 0, 0}, kEps, "op followed by its inverse");
  expect_vec3(apply(f.instances[4].model, {0, 0, 0}), {1, 0, 0}, kEps, "!resetXformStack! drops the parent");
  // Rows of the USD matrix are glm's columns (M: x -> y, y -> -x, translation (4,5,6)); the orient (90 about
  // Y) acts first: (1,0,0) -Ry90-> (0,0,-1) -M-> (4,5,5); (0,0,1) -Ry90-> (1,0,0) -M-> (4,6,6).
  expect_vec3(apply(f.instances[5].model, {1, 0, 0}), {4, 5, 5}, kEps, "orient then matrix on x");
  expect_vec3(apply(f.instances[5].model, {0, 0, 1}), {4, 6, 6}, kEps, "orient then matrix on z");
}

TEST_F(UsdScene, TimeSamplesInterpolateAndMapTimeCodesToSeconds) {
  Scene s = load(R"((
 startTimeCode = 1
 endTimeCode = 3
 timeCodesPerSecond = 24
 framesPerSecond = 24
)
def Xform "Move" {
 double3 xformOp:translate.timeSamples = {
  1: (0, 0, 0),
  3: (2, 0, 0),
 }
 quatf xformOp:orient.timeSamples = {
  1: (1, 0, 0, 0),
  3: (0.70710678, 0, 0.70710678, 0),
 }
 uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:orient"]
)" + triangle() + "}\n");
  // Timeline 1..3 at 24 time codes per second, the last frame held one frame: (3 - 1 + 1) / 24 s.
  EXPECT_DOUBLE_EQ(s.clip_duration(), 3.0 / 24.0);
  // t = 1/24 s is time code 2: halfway; the orientation slerps to 45 degrees about Y.
  const FrameState f = s.evaluate(1.0 / 24.0);
  expect_vec3(apply(f.instances[0].model, {0, 0, 0}), {1, 0, 0}, kEps, "translation at time code 2");
  const float c = std::cos(glm::quarter_pi<float>());
  expect_vec3(apply(f.instances[0].model, {1, 0, 0}) - glm::vec3(1, 0, 0), {c, 0, -c}, kEps, "slerped rotation");
  // Time code 1.5 (t = 0.5/24): a quarter of the way; the end value holds after time code 3.
  expect_vec3(apply(s.evaluate(0.5 / 24.0).instances[0].model, {0, 0, 0}), {0.5f, 0, 0}, kEps, "time code 1.5");
  expect_vec3(apply(s.evaluate(2.5 / 24.0).instances[0].model, {0, 0, 0}), {2, 0, 0}, kEps, "held after the last sample");
  const FrameRange frames = s.default_frames(24.0);
  EXPECT_EQ(frames.first, 0);
  EXPECT_EQ(frames.last, 2) << "time codes 1, 2, 3";
}

TEST_F(UsdScene, MeshesTriangulatePolygonsWithOrientationAndHoles) {
  Scene s = load(R"(def Mesh "Polys" {
 int[] faceVertexCounts = [4, 5, 3, 2]
 int[] faceVertexIndices = [0, 1, 2, 3, 4, 5, 6, 7, 8, 0, 1, 2, 0, 1]
 int[] holeIndices = [2]
 point3f[] points = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (2, 0, 0), (3, 0, 0), (3, 1, 0), (2.5, 2, 0), (2, 1, 0)]
 uniform token orientation = "leftHanded"
 uniform token subdivisionScheme = "none"
}
)");
  ASSERT_EQ(s.primitives().size(), 1u);
  const ScenePrimitive& p = s.primitives()[0];
  // Quad 0123 and pentagon 45678 fanned from their first vertex, winding flipped for leftHanded; the hole
  // (face 2) and the two-vertex face are skipped.
  EXPECT_EQ(p.indices, (std::vector<std::uint32_t>{0, 2, 1, 0, 3, 2, 4, 6, 5, 4, 7, 6, 4, 8, 7}));
  ASSERT_EQ(p.normals.size(), 9u);
  // Smooth normals of a flat polygon facing -Z after the flip.
  expect_vec3(p.normals[0], {0, 0, -1}, kEps, "generated normal");
  bool warned = false;
  for (const auto& w : s.warnings()) warned = warned || w.find("fewer than 3") != std::string::npos;
  EXPECT_TRUE(warned);
}

TEST_F(UsdScene, PrimvarInterpolationsIndicesAndTheStFlip) {
  Scene s = load(R"(def Mesh "Quad" {
 int[] faceVertexCounts = [4]
 int[] faceVertexIndices = [0, 1, 2, 3]
 point3f[] points = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]
 normal3f[] normals = [(0, 0, 1)] (
  interpolation = "uniform"
 )
 texCoord2f[] primvars:st = [(0, 0), (1, 0.25)] (
  interpolation = "faceVarying"
 )
 int[] primvars:st:indices = [0, 1, 1, 0]
 uniform token subdivisionScheme = "none"
}
)");
  const ScenePrimitive& p = s.primitives().at(0);
  // Uniform and faceVarying primvars: one vertex per face-vertex.
  ASSERT_EQ(p.positions.size(), 4u);
  ASSERT_EQ(p.texcoords.size(), 4u);
  EXPECT_EQ(p.texcoords[0], glm::vec2(0.0f, 1.0f)) << "t flipped to glTF's v = 1 - t";
  EXPECT_EQ(p.texcoords[1], glm::vec2(1.0f, 0.75f));
  EXPECT_EQ(p.texcoords[2], glm::vec2(1.0f, 0.75f)) << "indexed";
  EXPECT_EQ(p.texcoords[3], glm::vec2(0.0f, 1.0f));
  for (const auto& n : p.normals) expect_vec3(n, {0, 0, 1}, kEps, "uniform normal");
  EXPECT_EQ(p.indices, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3}));
}

TEST_F(UsdScene, CamerasFromLensAndClippingAnimatedOrNot) {
  const double va = 2.0 * 50.0 * std::tan(0.4);  // yfov 0.8 at focal length 50
  Scene s = load("(\n timeCodesPerSecond = 24\n startTimeCode = 0\n endTimeCode = 1\n)\n" + triangle() +
                 "def Camera \"Still\" {\n float focalLength = 50\n float verticalAperture = " + std::to_string(va) +
                 "\n float2 clippingRange = (0.5, 100)\n}\n"
                 "def Camera \"Zoom\" {\n float focalLength.timeSamples = {\n  0: 50,\n  1: 25,\n }\n float verticalAperture = 20\n}\n");
  const FrameState f = s.evaluate(0.0);
  EXPECT_EQ(f.camera.name, "Still") << "the first perspective camera";
  EXPECT_NEAR(f.camera.yfov, 0.8f, 1e-6f);
  EXPECT_FLOAT_EQ(f.camera.znear, 0.5f);
  EXPECT_FLOAT_EQ(f.camera.zfar, 100.0f);
  SceneLoadOptions zoom;
  zoom.camera.camera = "/Zoom";  // by prim path
  auto z = Scene::load((dir_ / "scene.usda").string(), zoom);
  ASSERT_TRUE(z) << z.error().message;
  // Time code 0.5: focal length 37.5.
  EXPECT_NEAR(z->evaluate(0.5 / 24.0).camera.yfov, 2.0 * std::atan(10.0 / 37.5), 1e-6);
  EXPECT_NEAR(z->evaluate(0.0).camera.yfov, 2.0 * std::atan(10.0 / 50.0), 1e-6);
}

TEST_F(UsdScene, UsdLuxLightsInPunctualUnits) {
  Scene s = load(triangle() + R"(def DistantLight "Sun" {
 float inputs:intensity = 2
 float inputs:exposure = 1
 color3f inputs:color = (1, 0.5, 0.25)
}
def SphereLight "Bulb" {
 float inputs:intensity = 1
 float inputs:radius = 0.5
}
def SphereLight "Normalized" {
 float inputs:intensity = 3
 bool inputs:normalize = 1
}
def RectLight "Panel" {
 float inputs:intensity = 1
 float inputs:width = 2
 float inputs:height = 3
}
def SphereLight "Spot" (
 prepend apiSchemas = ["ShapingAPI"]
) {
 bool inputs:normalize = 1
 float inputs:shaping:cone:angle = 30
 float inputs:shaping:cone:softness = 0.5
}
def DomeLight "Sky" {
 float inputs:intensity = 0.5
 color3f inputs:color = (1, 0.5, 0)
}
)");
  const FrameState f = s.evaluate(0.0);
  ASSERT_EQ(f.lights.size(), 5u);
  EXPECT_EQ(f.lights[0].type, LightState::Type::Directional);
  EXPECT_FLOAT_EQ(f.lights[0].intensity, 4.0f) << "intensity * 2^exposure, in lux";
  expect_vec3(f.lights[0].direction, {0, 0, -1}, kEps, "distant light along -Z");
  expect_vec3(f.lights[0].color, {1, 0.5f, 0.25f}, kEps, "colour");
  EXPECT_EQ(f.lights[1].type, LightState::Type::Point);
  EXPECT_NEAR(f.lights[1].intensity, glm::pi<float>() * 0.25f, 1e-6f) << "radiance * projected area pi r^2";
  EXPECT_FLOAT_EQ(f.lights[2].intensity, 3.0f) << "normalize: independent of the size";
  EXPECT_EQ(f.lights[3].type, LightState::Type::Spot);
  EXPECT_FLOAT_EQ(f.lights[3].intensity, 6.0f) << "radiance * area on the axis";
  EXPECT_FLOAT_EQ(f.lights[3].outer_cone, glm::half_pi<float>());
  EXPECT_EQ(f.lights[4].type, LightState::Type::Spot);
  EXPECT_NEAR(f.lights[4].outer_cone, glm::radians(30.0f), 1e-6f);
  EXPECT_NEAR(f.lights[4].inner_cone, glm::radians(15.0f), 1e-6f);
  expect_vec3(f.ambient, {0.5f, 0.25f, 0.0f}, kEps, "dome light as ambient radiance");
  expect_vec3(s.ambient(), {0.5f, 0.25f, 0.0f}, kEps, "Scene::ambient");
}

TEST_F(UsdScene, PreviewSurfaceMaterialsTexturesAndDisplayColor) {
  // A 2 x 2 RGBA texture; the top row is red, green (alpha 0 on green).
  const std::string png = (dir_ / "tex.png").string();
  const unsigned char pixels[16] = {255, 0, 0, 255, 0, 255, 0, 0, 0, 0, 255, 255, 255, 255, 255, 255};
  auto out = OIIO::ImageOutput::create(png);
  ASSERT_TRUE(out);
  ASSERT_TRUE(out->open(png, OIIO::ImageSpec(2, 2, 4, OIIO::TypeDesc::UINT8)));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, pixels));
  out->close();
  Scene s = load(R"(def Scope "Looks" {
 def Material "Plain" {
  token outputs:surface.connect = </Looks/Plain/S.outputs:surface>
  def Shader "S" {
   uniform token info:id = "UsdPreviewSurface"
   color3f inputs:diffuseColor = (0.2, 0.4, 0.6)
   float inputs:roughness = 0.3
   float inputs:metallic = 0.7
   color3f inputs:emissiveColor = (1, 2, 3)
   token outputs:surface
  }
 }
 def Material "Cut" {
  token outputs:surface.connect = </Looks/Cut/G.outputs:surface>
  def NodeGraph "G" {
   token outputs:surface.connect = </Looks/Cut/S.outputs:surface>
  }
  def Shader "S" {
   uniform token info:id = "UsdPreviewSurface"
   color3f inputs:diffuseColor.connect = </Looks/Cut/T.outputs:rgb>
   float inputs:opacity.connect = </Looks/Cut/T.outputs:a>
   float inputs:opacityThreshold = 0.5
  }
  def Shader "T" {
   uniform token info:id = "UsdUVTexture"
   asset inputs:file = @tex.png@
   float4 inputs:scale = (0.5, 0.5, 0.5, 1)
   token inputs:wrapS = "clamp"
   token inputs:wrapT = "mirror"
   float2 inputs:st.connect = </Looks/Cut/R.outputs:result>
  }
  def Shader "R" {
   uniform token info:id = "UsdPrimvarReader_float2"
   string inputs:varname = "uv"
  }
 }
}
)" + triangle("A", " rel material:binding = </Looks/Cut>\n texCoord2f[] primvars:uv = [(0, 0), (1, 0), (0, 1)] (\n  interpolation = \"vertex\"\n )\n uniform bool doubleSided = 1\n") +
                 "def Xform \"Group\" {\n rel material:binding = </Looks/Plain>\n" + triangle("B") + "}\n" +
                 triangle("C", " color3f[] primvars:displayColor = [(0.1, 0.2, 0.3)]\n"));
  ASSERT_EQ(s.materials().size(), 3u);
  // Materials in the order of their prims (Plain, Cut), then the display colour.
  const SceneMaterial& plain = s.materials()[0];
  EXPECT_EQ(plain.name, "Plain");
  EXPECT_EQ(plain.base_color_factor, glm::vec4(0.2f, 0.4f, 0.6f, 1.0f));
  EXPECT_FLOAT_EQ(plain.roughness, 0.3f);
  EXPECT_FLOAT_EQ(plain.metallic, 0.7f);
  EXPECT_EQ(plain.emissive, glm::vec3(1, 2, 3));
  const SceneMaterial& cut = s.materials()[1];
  EXPECT_EQ(cut.alpha_mode, SceneMaterial::AlphaMode::Mask);
  EXPECT_FLOAT_EQ(cut.alpha_cutoff, 0.5f);
  EXPECT_EQ(cut.base_color_factor, glm::vec4(0.5f, 0.5f, 0.5f, 1.0f)) << "the texture's scale";
  EXPECT_TRUE(cut.double_sided) << "from the mesh's doubleSided";
  ASSERT_EQ(cut.base_color_texture, 0);
  const SceneTexture& t = s.textures()[0];
  EXPECT_EQ(t.width, 2);
  EXPECT_EQ((std::vector<std::uint8_t>(t.rgba8.begin(), t.rgba8.begin() + 8)),
            (std::vector<std::uint8_t>{255, 0, 0, 255, 0, 255, 0, 0})) << "top row first, alpha not premultiplied";
  EXPECT_TRUE(t.srgb);
  EXPECT_FALSE(t.repeat_s);
  EXPECT_TRUE(t.mirror_t);
  EXPECT_EQ(s.materials()[2].name, "displayColor");
  EXPECT_EQ(s.materials()[2].base_color_factor, glm::vec4(0.1f, 0.2f, 0.3f, 1.0f));
  // The primvar the texture reads ("uv") is the primitive's texcoords, flipped.
  const ScenePrimitive& a = s.primitives()[0];
  ASSERT_EQ(a.texcoords.size(), 3u);
  EXPECT_EQ(a.texcoords[1], glm::vec2(1.0f, 1.0f));
  EXPECT_EQ(s.primitives()[1].material, 0) << "a binding on an ancestor applies";
}

// Two joints: "a" at the origin and "a/b" one unit up, b turned 90 degrees about Z by the animation.
const char* const kSkeleton = R"(def SkelRoot "Root" {
 def Skeleton "Skel" (
  prepend apiSchemas = ["SkelBindingAPI"]
 ) {
  uniform token[] joints = ["a", "a/b"]
  uniform matrix4d[] bindTransforms = [( (1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0), (0, 0, 0, 1) ), ( (1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0), (0, 1, 0, 1) )]
  uniform matrix4d[] restTransforms = [( (1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0), (0, 0, 0, 1) ), ( (1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0), (0, 1, 0, 1) )]
  rel skel:animationSource = <Anim>
  def SkelAnimation "Anim" {
   uniform token[] joints = ["a/b", "a"]
   quatf[] rotations = [(0.70710678, 0, 0, 0.70710678), (1, 0, 0, 0)]
   float3[] translations = [(0, 1, 0), (0, 0, 0)]
   half3[] scales = [(1, 1, 1), (1, 1, 1)]
   uniform token[] blendShapes = ["up"]
   float[] blendShapeWeights = [0.25]
  }
 }
 def Mesh "Skinned" (
  prepend apiSchemas = ["SkelBindingAPI"]
 ) {
  int[] faceVertexCounts = [3]
  int[] faceVertexIndices = [0, 1, 2]
  point3f[] points = [(-1, 2, 0), (0, 1, 0), (1, 1, 0)]
  int[] primvars:skel:jointIndices = [1, 0, 0, 1, 0, 1] (
   elementSize = 2
   interpolation = "vertex"
  )
  float[] primvars:skel:jointWeights = [1, 0, 0.5, 0.5, 0.5, 0.5] (
   elementSize = 2
   interpolation = "vertex"
  )
  matrix4d primvars:skel:geomBindTransform = ( (1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0), (1, 0, 0, 1) )
  uniform token subdivisionScheme = "none"
  uniform token[] skel:blendShapes = ["up"]
  rel skel:blendShapeTargets = [<Up>]
  rel skel:skeleton = </Root/Skel>
  def BlendShape "Up" {
   uniform vector3f[] offsets = [(0, 0, 4)]
   uniform int[] pointIndices = [2]
  }
 }
}
)";

TEST_F(UsdScene, SkelLinearBlendSkinningAndBlendShapes) {
  Scene s = load(kSkeleton);
  const FrameState f = s.evaluate(0.0);
  ASSERT_EQ(f.instances.size(), 1u);
  const PrimitiveInstance& inst = f.instances[0];
  ASSERT_TRUE(inst.deformed);
  ASSERT_EQ(inst.world_positions.size(), 3u);
  // Point 0 (-1,2,0), geomBind -> (0,2,0); joint b: inverse bind -> (0,1,0), Rz90 -> (-1,0,0), + (0,1,0) = (-1,1,0).
  expect_vec3(inst.world_positions[0], {-1, 1, 0}, kEps, "rigid on joint b");
  // Point 1 (0,1,0) -> (1,1,0): joint a keeps it, joint b: (1,0,0) -> (0,1,0) + (0,1,0) = (0,2,0); half each.
  expect_vec3(inst.world_positions[1], {0.5f, 1.5f, 0}, kEps, "blended");
  // Point 2 (1,1,0) + 0.25 * (0,0,4) = (1,1,1) before skinning -> (2,1,1); a: (2,1,1); b: (2,0,1) -> (0,2,1) + (0,1,0).
  expect_vec3(inst.world_positions[2], {1.0f, 2.0f, 1.0f}, kEps, "blend shape then skinning");
  EXPECT_TRUE(s.primitives()[0].skinned);
  EXPECT_TRUE(s.primitives()[0].morphed);
}

TEST_F(UsdScene, SkinningNeedsASkelRoot) {
  std::string text = kSkeleton;
  text.replace(text.find("def SkelRoot"), 12, "def Xform");
  Scene s = load(text);
  const FrameState f = s.evaluate(0.0);
  EXPECT_FALSE(f.instances.at(0).deformed) << "UsdSkel deforms nothing outside a SkelRoot (baked files)";
}

TEST_F(UsdScene, OnlyActiveDefinedVisibleRenderPrimsAreDrawn) {
  Scene s = load(triangle("Drawn") + R"(def Xform "Hidden" {
 token visibility = "invisible"
)" + triangle("Below") + R"(}
def Xform "Guide" {
 uniform token purpose = "guide"
)" + triangle("G") + "}\n" + triangle("Render", " uniform token purpose = \"render\"\n") +
                 "def Xform \"Off\" (\n active = false\n) {\n" + triangle("O") + "}\nover \"Over\" {\n" + triangle("V") +
                 "}\nclass \"Class\" {\n" + triangle("K") + "}\n");
  EXPECT_EQ(s.evaluate(0.0).instances.size(), 2u) << "Drawn and Render";
}

TEST_F(UsdScene, ZUpStagesTurnToYUp) {
  Scene s = load("(\n upAxis = \"Z\"\n)\n" + triangle());
  expect_vec3(apply(s.evaluate(0.0).instances.at(0).model, {0, 0, 1}), {0, 1, 0}, kEps, "+Z becomes +Y");
}

TEST_F(UsdScene, RefusalsAndErrors) {
  const std::string scene = write("scene.usda", triangle());
  SceneLoadOptions clip;
  clip.clip = "Walk";
  auto c = Scene::load(scene, clip);
  ASSERT_FALSE(c);
  EXPECT_EQ(c.error().kind, ErrorKind::Usage);

  std::ofstream(dir_ / "binary.usd") << "PXR-USDC" << std::string(88, '\0');
  auto crate = Scene::load((dir_ / "binary.usd").string());
  ASSERT_FALSE(crate);
  EXPECT_NE(crate.error().message.find("usdcat -o file.usda binary.usd"), std::string::npos) << crate.error().message;
  std::ofstream(dir_ / "package.usdz") << "PK\x03\x04" << std::string(60, '\0');
  auto zip = Scene::load((dir_ / "package.usdz").string());
  ASSERT_FALSE(zip);
  EXPECT_NE(zip.error().message.find(".usdz"), std::string::npos) << zip.error().message;
  std::ofstream(dir_ / "garbage.usda") << "{ \"not\": \"usd\" }";
  auto garbage = Scene::load((dir_ / "garbage.usda").string());
  ASSERT_FALSE(garbage);
  EXPECT_NE(garbage.error().message.find("#usda 1.0"), std::string::npos) << garbage.error().message;
  // USD recognised by content whatever the extension.
  fs::copy_file(scene, dir_ / "scene.txt");
  EXPECT_TRUE(Scene::load((dir_ / "scene.txt").string()));

  auto bad = Scene::load(write("bad.usda", "def Mesh \"M\" {\n int[] faceVertexCounts = [3]\n int[] faceVertexIndices = [0, 1, 7]\n"
                                           " point3f[] points = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]\n}\n"));
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().file, (dir_ / "bad.usda").string() + ":2:1");
  EXPECT_NE(bad.error().message.find("out of range"), std::string::npos) << bad.error().message;
  auto ops = Scene::load(write("ops.usda", "def Xform \"X\" {\n uniform token[] xformOpOrder = [\"xformOp:translate\"]\n" + triangle() + "}\n"));
  ASSERT_FALSE(ops);
  EXPECT_NE(ops.error().message.find("does not have"), std::string::npos) << ops.error().message;
  auto empty = Scene::load(write("empty.usda", "def Xform \"X\" {}\n"));
  ASSERT_FALSE(empty);
  EXPECT_NE(empty.error().message.find("no mesh"), std::string::npos);
}

}  // namespace
}  // namespace temporal
