// The renderer through EGL beside OSMesa (issue 22): on this machine EGL's device platform offers Mesa's software
// device, the same llvmpipe that OSMesa runs, so a built-in scene must render bit-identically through both contexts
// (every plane of the G-buffer, the payload, the colour and the reference), and every image must say which context
// and renderer made it.
#include "test_support.h"

#include "temporal/render/render.h"
#include "temporal/scene/scene.h"

#include <gtest/gtest.h>

#include <cstring>

namespace temporal {
namespace {

// Bit-identity of every channel (float and uint), as an assertion naming the first plane that differs and how
// many of its pixels do.
::testing::AssertionResult same_bits(const Image& a, const Image& b) {
  if (a.width() != b.width() || a.height() != b.height()) return ::testing::AssertionFailure() << "sizes differ";
  if (a.channel_names() != b.channel_names()) return ::testing::AssertionFailure() << "channel lists differ";
  for (const auto& c : a.channel_names()) {
    const bool u = a.channel_type(c) == ChannelType::UInt;
    const auto* pa = u ? static_cast<const void*>(a.uint_plane(c)) : static_cast<const void*>(a.plane(c));
    const auto* pb = u ? static_cast<const void*>(b.uint_plane(c)) : static_cast<const void*>(b.plane(c));
    std::size_t differ = 0;
    for (std::size_t i = 0; i < a.pixel_count(); ++i)
      differ += std::memcmp(static_cast<const char*>(pa) + 4 * i, static_cast<const char*>(pb) + 4 * i, 4) != 0;
    if (differ) return ::testing::AssertionFailure() << c << ": " << differ << " of " << a.pixel_count() << " pixels differ";
  }
  return ::testing::AssertionSuccess();
}

RenderOptions small_options(GlApi api) {
  RenderOptions o;
  o.width = 64;
  o.height = 48;
  o.reference_spp = 3;
  o.payload.shadow_map_size = 256;
  o.payload.vpl_count = 64;
  o.payload.rsm_size = 32;
  o.gl = api;
  return o;
}

TEST(RenderEgl, ListsTheSoftwareDevice) {
  auto devices = list_gl_devices();
  ASSERT_TRUE(devices) << devices.error().message;
  bool software = false;
  for (const GlDevice& d : *devices) {
    EXPECT_TRUE(d.error.empty()) << d.index << ": " << d.error;
    if (d.software) {
      software = true;
      EXPECT_EQ(d.renderer.rfind("llvmpipe", 0), 0u) << d.renderer;
      EXPECT_NE(d.version.find("4.5"), std::string::npos) << d.version;
      EXPECT_NE(d.extensions.find("EGL_MESA_device_software"), std::string::npos) << d.extensions;
    }
  }
  EXPECT_TRUE(software) << "no EGL_MESA_device_software device (is libegl-mesa0 installed?)";
}

TEST(RenderEgl, ADeviceBeyondTheListIsAUsageError) {
  auto devices = list_gl_devices();
  ASSERT_TRUE(devices) << devices.error().message;
  RenderOptions o = small_options(GlApi::Egl);
  o.gl_device = int(devices->size());
  std::vector<ScenePrimitive> primitives;
  std::vector<SceneMaterial> materials;
  std::vector<SceneTexture> textures;
  SceneGeometry g;
  g.primitives = &primitives;
  g.materials = &materials;
  g.textures = &textures;
  auto r = Renderer::create(o, g);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().kind, ErrorKind::Usage) << r.error().message;
  EXPECT_NE(r.error().message.find("--gl-device"), std::string::npos) << r.error().message;
}

// Frames 5-7 of a built-in scene (skinned walkers: textures, alpha, every payload term), each rendered by the
// renderers given, which live side by side and take turns on the thread frame by frame.
struct Frames {
  std::vector<RenderedFrame> of[2];
};
void render_frames(const Scene& scene, std::vector<Renderer*> renderers, Frames& out) {
  const double fps = 40.0;
  FrameState previous = scene.evaluate(4 / fps);
  for (int frame = 5; frame <= 7; ++frame) {
    const FrameState current = scene.evaluate(frame / fps);
    FrameInput in;
    in.frame = frame;
    in.fps = fps;
    in.current = &current;
    in.previous = &previous;
    for (std::size_t k = 0; k < renderers.size(); ++k) {
      auto r = renderers[k]->render(in);
      ASSERT_TRUE(r) << r.error().message;
      out.of[k].push_back(std::move(*r));
    }
    previous = current;
  }
}

void expect_same_frames(const std::vector<RenderedFrame>& a, const std::vector<RenderedFrame>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t f = 0; f < a.size(); ++f)
    for (auto [name, x, y] : {std::tuple{"gbuffer", &a[f].gbuffer, &b[f].gbuffer}, {"shade", &a[f].shade, &b[f].shade},
                              {"reference", &a[f].reference, &b[f].reference}, {"color", &a[f].color, &b[f].color}}) {
      ASSERT_TRUE(x->has_value() && y->has_value()) << name;
      EXPECT_TRUE(same_bits(**x, **y)) << name << " frame " << 5 + f;
    }
}

Expected<Scene> walkers() { return Scene::load((test::source_dir() / "assets" / "scenes" / "walkers.glb").string()); }

// One renderer after the other: the same llvmpipe behind either context writes the same bits.
TEST(RenderEgl, BuiltInSceneIsBitIdenticalThroughOsmesaAndEgl) {
  auto scene = walkers();
  ASSERT_TRUE(scene) << scene.error().message;
  Frames osmesa_frames, egl_frames;
  std::string osmesa_renderer;
  {
    auto osmesa = Renderer::create(small_options(GlApi::OSMesa), geometry_of(*scene));
    ASSERT_TRUE(osmesa) << osmesa.error().message;
    EXPECT_EQ(osmesa->gl_info().context, "osmesa");
    osmesa_renderer = osmesa->gl_info().renderer;
    render_frames(*scene, {&*osmesa}, osmesa_frames);
  }
  auto egl = Renderer::create(small_options(GlApi::Egl), geometry_of(*scene));
  ASSERT_TRUE(egl) << egl.error().message;
  EXPECT_EQ(egl->gl_info().context, "egl");
  EXPECT_EQ(egl->gl_info().renderer, osmesa_renderer);  // both llvmpipe: the premise of bit-identity
  render_frames(*scene, {&*egl}, egl_frames);
  expect_same_frames(osmesa_frames.of[0], egl_frames.of[0]);
  for (std::size_t f = 0; f < egl_frames.of[0].size(); ++f) {
    const RenderedFrame& a = osmesa_frames.of[0][f];
    const RenderedFrame& b = egl_frames.of[0][f];
    for (const Image* x : {&*a.gbuffer, &*a.shade, &*a.reference, &*a.color}) {
      // The images say which context made them (the `temporal:gl*` header attributes).
      EXPECT_EQ(x->metadata().extra.at("glContext"), "osmesa");
      EXPECT_EQ(x->metadata().extra.count("glDevice"), 0u);
      EXPECT_EQ(x->metadata().extra.at("glRenderer"), osmesa_renderer);
      EXPECT_FALSE(x->metadata().extra.at("glVersion").empty());
      EXPECT_FALSE(x->metadata().extra.at("glVendor").empty());
    }
    for (const Image* y : {&*b.gbuffer, &*b.shade, &*b.reference, &*b.color}) {
      EXPECT_EQ(y->metadata().extra.at("glContext"), "egl");
      EXPECT_EQ(y->metadata().extra.at("glDevice"), std::to_string(egl->gl_info().device));
      EXPECT_EQ(y->metadata().extra.at("glRenderer"), egl->gl_info().renderer);
    }
    // Not blank: the comparison means something.
    float sum = 0.0f;
    for (std::size_t i = 0; i < a.color->pixel_count(); ++i) sum += a.color->plane("R")[i];
    EXPECT_GT(sum, 0.0f);
  }
}

// An OSMesa and an EGL renderer alive together, taking turns: each must draw on its own context (make_current).
// Their sizes differ, so a renderer drawing on the other's context (whose objects carry the same names) would not
// reproduce its own render made alone on the other kind of context.
TEST(RenderEgl, OsmesaAndEglRenderersTakeTurnsOnOneThread) {
  auto scene = walkers();
  ASSERT_TRUE(scene) << scene.error().message;
  RenderOptions big = small_options(GlApi::OSMesa), little = small_options(GlApi::Egl);
  little.width = 32;
  little.height = 24;
  Frames together, alone_big, alone_little;
  {
    auto a = Renderer::create(big, geometry_of(*scene));
    ASSERT_TRUE(a) << a.error().message;
    auto b = Renderer::create(little, geometry_of(*scene));
    ASSERT_TRUE(b) << b.error().message;
    render_frames(*scene, {&*a, &*b}, together);
  }
  big.gl = GlApi::Egl;
  little.gl = GlApi::OSMesa;
  {
    auto a = Renderer::create(big, geometry_of(*scene));
    ASSERT_TRUE(a) << a.error().message;
    render_frames(*scene, {&*a}, alone_big);
  }
  {
    auto b = Renderer::create(little, geometry_of(*scene));
    ASSERT_TRUE(b) << b.error().message;
    render_frames(*scene, {&*b}, alone_little);
  }
  expect_same_frames(together.of[0], alone_big.of[0]);
  expect_same_frames(together.of[1], alone_little.of[0]);
}

// llvmpipe accepts timer queries but reads 0: the renderer must not report such times as device times.
TEST(RenderEgl, NoDeviceTimesFromASoftwareDevice) {
  auto scene = Scene::load((test::source_dir() / "assets" / "scenes" / "tower.glb").string());
  ASSERT_TRUE(scene) << scene.error().message;
  RenderOptions o = small_options(GlApi::Egl);
  o.gpu_timer = true;
  o.outputs = {true, false, false, false};
  auto r = Renderer::create(o, geometry_of(*scene));
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_FALSE(r->has_gpu_timer());
  const FrameState s = scene->evaluate(0.0);
  FrameInput in;
  in.current = &s;
  auto out = r->render(in);
  ASSERT_TRUE(out) << out.error().message;
  EXPECT_TRUE(out->gpu_ms.empty());
  EXPECT_TRUE(out->timings_ms.count(kPassGbuffer));
}

}  // namespace
}  // namespace temporal
