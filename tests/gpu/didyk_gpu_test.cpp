// morph-120hz's `didyk` GPU kernels (didyk_gpu.cpp) against the C++ reference of record (didyk.cpp): synthetic
// frames with known motion (an analytic texture; a foreground square and a swirling background moving apart, so the
// grid snaps, cells stretch and fold over, and the depth test decides overlaps), at factor 3 (the rendered
// sequence: didyk_render_gpu_test.cpp). Why the two are not bit for bit equal: didyk_gpu_support.h.
#include "didyk_gpu_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace {

using namespace temporal;
using namespace temporal::test::didyk;
using morph::MorphMethod;
using morph::MorphOptions;
using morph::MorphTimings;

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
