// morph-120hz's `didyk` GPU kernels (didyk_gpu.cpp) against the C++ reference of record (didyk.cpp): synthetic
// frames with known motion (an analytic texture; a foreground square and a swirling background moving apart, so the
// grid snaps, cells stretch and fold over, and the depth test decides overlaps), and a small sequence rendered by
// the renderer (tests/render/synthetic_scene.h: camera, node and vertex motion), at factor 3.
//
// Why the outputs are not bit for bit equal (measured values and bounds in docs/gpu.md, "Tolerances"):
//  - float rounding: GCC (-march=native) contracts multiply-adds into FMAs where it chooses (the B-spline row and
//    column sums of the blur, the [1 2 1]/4 pyramid, the barycentric interpolation of texture coordinates and
//    attributes, the compensation's (1 + B) o - B L^g), and the driver chooses its own; the fast log2/exp2 of
//    core/fast_math.h are the same polynomials with the same constants (bit patterns), but their division
//    (m - 1) / (m + 1) and the same contractions differ in the last bit. This moves values by a few 1e-7.
//  - decisions taken on those values: where a texture coordinate rounded differently lands exactly on a pixel
//    border, the nearest source pixel of the depth test or a bilinear tap changes, and that pixel shows a neighbour's
//    value. What the rasteriser decides in double (coverage, the top-left rule, the barycentric weights) is computed
//    from floats whose products fit a double's mantissa at these coordinate sizes, so an FMA or not gives the same
//    bits on both sides and no pixel changes triangle (measured: debug.grid and the coverage are equal).
#include "morph_gpu_support.h"
#include "synthetic_scene.h"  // tests/render
#include "temporal/core/method.h"
#include "temporal/gpu/timer.h"
#include "temporal/morph/gpu_methods.h"
#include "temporal/morph/methods.h"
#include "temporal/render/render.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace {

using namespace temporal;
using morph::MorphMethod;
using morph::MorphOptions;
using morph::MorphTimings;

const std::vector<std::string> kRgb = {"R", "G", "B"};

struct Frame {
  Image color, gbuffer;
};

// Smooth texture in [0.1, 0.6] plus a bright stripe pattern (values up to 0.95, so the compensation's range rules
// act) over 83 x 61 pixels (not multiples of the 16 x 16 work group or of the 8-pixel grid cell). The square (depth
// 4) moves by (5.3, -2.7) px per frame; the background (depth 20) pans by (-1.6, 0.9) with a swirl of up to 1.5 px.
Frame synthetic_frame(int t) {
  const int w = 83, h = 61;
  Frame f;
  f.color = Image(w, h);
  f.gbuffer = Image(w, h);
  float* mx = f.gbuffer.add_channel("motion.X");
  float* my = f.gbuffer.add_channel("motion.Y");
  float* d = f.gbuffer.add_channel("depth.Z");
  for (int c = 0; c < 3; ++c) {
    float* p = f.color.add_channel(kRgb[std::size_t(c)]);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const float u = float(x) + 0.5f + 7.0f * float(t), v = float(y) + 0.5f;
        const float base = 0.35f + 0.15f * std::sin(0.45f * u + 0.7f * float(c)) * std::cos(0.6f * v);
        p[y * w + x] = ((x + 2 * y) % 11 == 0) ? 0.95f : base;
      }
  }
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int i = y * w + x;
      const bool sq = x >= 20 && x < 50 && y >= 15 && y < 40;
      mx[i] = sq ? 5.3f : -1.6f + 1.5f * std::sin(0.11f * float(y) + 0.3f * float(t));
      my[i] = sq ? -2.7f : 0.9f + 1.2f * std::cos(0.09f * float(x));
      d[i] = sq ? 4.0f : 20.0f + 0.01f * float(x % 3);
    }
  return f;
}

// A small rendered sequence: the renderer's synthetic scene (textured ground, a moving box, a deformed strip) with
// camera, node and vertex motion, 96 x 72, at 10 fps (several pixels of motion per frame). Colour R,G,B and the
// G-buffer's motion and depth; an error when the renderer cannot run here.
std::vector<Frame> rendered_sequence(int frames, std::string* error) {
  test::SyntheticScene scene;
  scene.motion = test::SyntheticScene::kCamera | test::SyntheticScene::kNode | test::SyntheticScene::kDeform;
  RenderOptions o;
  o.width = 96;
  o.height = 72;
  o.factor = 4;
  o.outputs = RenderOutputs{true, false, false, true};
  // Through EGL, not OSMesa: an OSMesa context made current on this thread takes over Mesa's GL dispatch while EGL
  // still reports the kernels' context as current, so gpu::Context::make_current() would not switch back (the
  // renderer's EGL context is switched away from properly). The images are the same either way on llvmpipe.
  o.gl = GlApi::Egl;
  o.payload.shadow_map_size = 256;
  o.payload.vpl_count = 64;
  o.payload.rsm_size = 32;
  o.payload.ssao_directions = 4;
  o.payload.ssao_steps = 4;
  auto r = Renderer::create(o, scene.geometry());
  if (!r) {
    *error = r.error().message;
    return {};
  }
  const double fps = 10.0;
  std::vector<Frame> out;
  for (int n = 1; n <= frames; ++n) {
    const FrameState cur = scene.evaluate(n / fps), prev = scene.evaluate((n - 1) / fps);
    FrameInput in;
    in.frame = n;
    in.fps = fps;
    in.current = &cur;
    in.previous = &prev;
    auto frame = r->render(in);
    if (!frame) {
      *error = frame.error().message;
      return {};
    }
    out.push_back({*frame->color, *frame->gbuffer});
  }
  return out;
}

struct Outcome {
  test::Agreement colour;            // R, G, B of every slot (values beyond 1e-5 counted)
  test::Agreement debug_values;      // debug.distortion, debug.blur, debug.H, debug.Hprime
  std::size_t grid_pixels = 0;       // pixels of debug.grid set in the C++ output
  std::size_t grid_differing = 0;    // ... and pixels of debug.grid that differ
};

// Runs the C++ method (the registry's kCpuDevice implementation) and the GPU one on `frames` and compares every
// slot.
Outcome compare(std::shared_ptr<gpu::Context> ctx, const std::vector<Frame>& frames, const std::vector<std::string>& args,
                bool debug, float pixels_per_degree = 0.0f) {
  auto options = morph::make_options("didyk", args);
  EXPECT_TRUE(options) << options.error().message;
  Outcome r;
  if (!options) return r;
  options->factor = 3;
  options->debug_layers = debug;
  options->pixels_per_degree = pixels_per_degree;
  const morph::MethodEntry* entry = morph::find_entry("didyk");
  const auto* cpu_impl = find_implementation(*entry, kCpuDevice);
  EXPECT_TRUE(cpu_impl);
  if (!cpu_impl) return r;
  auto cpu = cpu_impl->make(*options);
  auto gpu = make_didyk_method_gpu(ctx, *options);
  EXPECT_TRUE(gpu) << gpu.error().message;
  if (!gpu) return r;
  for (const Frame& f : frames) {
    std::vector<Image> a = test::stale_slots(std::size_t(options->factor), f.color.width(), f.color.height(), debug);
    std::vector<Image> b = a;
    MorphTimings ta, tb;
    cpu->run(f.color, &f.gbuffer, nullptr, a, ta);
    (*gpu)->run(f.color, &f.gbuffer, nullptr, b, tb);
    EXPECT_TRUE((*gpu)->run_status()) << (*gpu)->run_status().error().message;
    r.colour.merge(test::slots_agreement(b, a, kRgb, 1e-5));
    if (debug) {
      r.debug_values.merge(test::slots_agreement(b, a, {"debug.distortion", "debug.blur", "debug.H", "debug.Hprime"}));
      for (std::size_t k = 0; k < a.size(); ++k) {
        const float* grid = a[k].plane("debug.grid");
        r.grid_pixels +=
            std::size_t(std::count_if(grid, grid + f.color.pixel_count(), [](float v) { return v != 0.0f; }));
        r.grid_differing += test::differing_values(b[k], a[k], "debug.grid");
      }
    }
    const auto* timed = dynamic_cast<const gpu::TimedKernel*>(gpu->get());
    EXPECT_TRUE(timed && timed->last_timing().kernel_ms > 0.0 && timed->last_timing().bytes_moved > 0.0);
    EXPECT_GT(tb.total_ms(), 0.0);
  }
  return r;
}

void report(const char* what, const Outcome& r) {
  std::printf("%s: colour max |GPU - CPU| %.3g, PSNR %.1f dB, %zu of %zu values beyond 1e-5; debug values max %.3g; "
              "debug.grid %zu of %zu pixels differ\n",
              what, r.colour.max_abs, r.colour.psnr, r.colour.values_beyond, r.colour.values, r.debug_values.max_abs,
              r.grid_differing, r.grid_pixels);
}

std::vector<Frame> synthetic_frames() { return {synthetic_frame(0), synthetic_frame(1), synthetic_frame(2)}; }

// Synthetic motion, factor 3, the variants that change the kernels' paths: defaults (snapped grid, blur level 2,
// compensation), a regular grid, a fractional blur level (two pyramid levels blended), no compensation, a 4-pixel
// grid, a blur floor, and the eye-tracking limit (15 px per degree at 40 fps: the square's 6 px per frame are
// 16 deg/s, below the limit; at 2 px per degree 120 deg/s: damped to 0). Measured on llvmpipe (2026-11-26): colour
// max |GPU - CPU| 5.9e-6 to 1.02e-5, PSNR 126.0-128.8 dB, at most 1 value in 136701 beyond 1e-5; debug values
// (distortion, blur, H, H') 2.7e-6; debug.grid equal. Bounds: colour max 1e-4 and PSNR 110 dB, at most 0.1 % of
// the values beyond 1e-5 (where rounding moves a texture coordinate across a pixel border), debug values 2e-5,
// debug.grid 1 % of its pixels (a line's step position float(s) / float(steps) is the driver's division).
TEST(DidykGpu, MatchesTheCppMethodOnSyntheticMotion) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  const std::vector<Frame> frames = synthetic_frames();
  struct Variant {
    const char* name;
    std::vector<std::string> args;
    float ppd;
  };
  const std::vector<Variant> variants = {
      {"defaults", {}, 0.0f},
      {"no snap", {"--no-snap"}, 0.0f},
      {"blur level 1.5", {"--blur-level", "1.5"}, 0.0f},
      {"no compensation", {"--no-compensation"}, 0.0f},
      {"grid 4, min blur 0.3", {"--grid", "4", "--min-blur", "0.3"}, 0.0f},
      {"eye tracking 15 ppd", {}, 15.0f},
      {"eye tracking 2 ppd", {}, 2.0f},
  };
  for (const Variant& v : variants)
    for (const bool debug : {false, true}) {
      SCOPED_TRACE(::testing::Message() << v.name << (debug ? ", debug layers" : ""));
      const Outcome r = compare(ctx, frames, v.args, debug, v.ppd);
      report(v.name, r);
      EXPECT_LE(r.colour.max_abs, 1e-4);
      EXPECT_GE(r.colour.psnr, 110.0);
      EXPECT_LE(r.colour.share_beyond(), 1e-3);
      EXPECT_EQ(r.colour.finiteness_mismatches, 0u);
      if (debug) {
        EXPECT_LE(r.debug_values.max_abs, 2e-5);
        EXPECT_EQ(r.debug_values.finiteness_mismatches, 0u);
        EXPECT_GT(r.grid_pixels, 0u);
        EXPECT_LE(double(r.grid_differing), 0.01 * double(r.grid_pixels));
      }
    }
}

// The issue's requirement: at least 50 dB between the GPU and the C++ outputs on a rendered sequence (3 frames,
// factor 3, defaults and debug layers). Measured on llvmpipe (2026-11-26): colour max |GPU - CPU| 9.0e-6, PSNR
// 125.0 dB, no value beyond 1e-5; debug values 2.2e-6, debug.grid equal. Bounds as above (PSNR 110 dB: the issue's
// 50 dB with a wide margin); rendered colour is HDR (values above 1 pass through the compensation unchanged).
TEST(DidykGpu, MatchesTheCppMethodOnARenderedSequence) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  std::string error;
  const std::vector<Frame> frames = rendered_sequence(3, &error);
  ASSERT_EQ(frames.size(), 3u) << error;
  for (const bool debug : {false, true}) {
    SCOPED_TRACE(::testing::Message() << "debug layers " << debug);
    const Outcome r = compare(ctx, frames, {}, debug);
    report("rendered", r);
    EXPECT_GE(r.colour.psnr, 110.0);
    EXPECT_GE(r.colour.psnr, 50.0) << "issue 23's bound";
    EXPECT_LE(r.colour.max_abs, 1e-4);
    EXPECT_LE(r.colour.share_beyond(), 1e-3);
    EXPECT_EQ(r.colour.finiteness_mismatches, 0u);
    if (debug) {
      EXPECT_LE(r.debug_values.max_abs, 2e-5);
      EXPECT_LE(double(r.grid_differing), 0.01 * double(r.grid_pixels));
    }
  }
}

// Independent of the C++ method: without motion nothing is distorted, so no in-between frame is blurred (B = 0):
// slot 0 is the rendered frame bit for bit (no compensation where B = 0), and every in-between slot shows it up to
// the rounding of the interpolated texture coordinate (w0 u0 + w1 u1 + w2 u2 in float lands a few ulps, at most
// ~3e-5 px at x < 83, from the pixel centre; the stripes step by 0.6 per pixel: at most ~2e-5, bound 1e-4). A wrong
// grid, raster, blur sum or blend shows here by a large margin (the texture changes by ~0.07 per pixel, the stripes
// by 0.6).
TEST(DidykGpu, StaticFrameIsShownInEverySlot) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  Frame f = synthetic_frame(0);
  for (const char* c : {"motion.X", "motion.Y"}) std::fill(f.gbuffer.plane(c), f.gbuffer.plane(c) + f.gbuffer.pixel_count(), 0.0f);
  MorphOptions options;
  options.factor = 3;
  auto gpu = make_didyk_method_gpu(ctx, options);
  ASSERT_TRUE(gpu) << gpu.error().message;
  std::vector<Image> out = test::stale_slots(3, f.color.width(), f.color.height(), false);
  MorphTimings t;
  (*gpu)->run(f.color, &f.gbuffer, nullptr, out, t);
  ASSERT_TRUE((*gpu)->run_status());
  for (std::size_t k = 0; k < out.size(); ++k)
    for (const auto& c : kRgb)
      for (std::size_t i = 0; i < f.color.pixel_count(); ++i) {
        if (k == 0)
          ASSERT_EQ(out[k].plane(c)[i], f.color.plane(c)[i]) << "slot 0 " << c << " pixel " << i;
        else
          ASSERT_NEAR(out[k].plane(c)[i], f.color.plane(c)[i], 1e-4) << "slot " << k << " " << c << " pixel " << i;
      }
}

// didyk's registry entry has the GPU implementation beside the C++ one (device "gpu"); through the registry's
// factory it runs like the direct factory. Invalid didyk options are usage errors of the factory, and come back from
// the registry's method's run_status().
TEST(DidykGpu, IsRegisteredAsTheGpuImplementation) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  const morph::MethodEntry* entry = morph::find_entry("didyk");
  ASSERT_TRUE(entry);
  EXPECT_EQ(implementation_devices(*entry), (std::vector<std::string>{kCpuDevice, kGpuDevice}));
  const auto* impl = find_implementation(*entry, kGpuDevice);
  ASSERT_TRUE(impl);
  EXPECT_TRUE(impl->make.needs_gpu()) << "the registry holds the GPU factory itself: the tool hands it its context";
  MorphOptions options;
  options.factor = 3;
  auto method = impl->make(ctx, options);
  ASSERT_TRUE(method) << method.error().message;
  const Frame f = synthetic_frame(1);
  std::vector<Image> out = test::stale_slots(3, f.color.width(), f.color.height(), false);
  MorphTimings t;
  (*method)->run(f.color, &f.gbuffer, nullptr, out, t);
  EXPECT_TRUE((*method)->run_status()) << (*method)->run_status().error().message;
  EXPECT_NE(dynamic_cast<const gpu::TimedKernel*>(method->get()), nullptr);

  // --grid 6 passes the range check of the command line but not didyk's own (a power of two); the registry's
  // factory says so.
  MorphOptions six;
  ASSERT_TRUE(apply_args(morph::params(six), {"--grid", "6"}));
  auto refused = impl->make(ctx, six);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("power of two"), std::string::npos) << refused.error().message;
}

}  // namespace
