// upsample-st's GPU kernels against their C++ implementations on a rendered sequence: the built-in walkers scene
// (skinned figures walking: disocclusions behind them every frame, textures, the full payload) rendered by
// render-gbuffer's library at 64x48 with k = 4, 8 frames with a cut after the fourth, with the renderer's own warped
// depth (prevDepth.Z) and ids. The synthetic tests (herzog_gpu_test.cpp, taau_gpu_test.cpp, upsample_gpu_test.cpp)
// cover every option; this one checks that real G-buffers (HDR payload, skinned motion, silhouettes) keep the same
// agreement. The method states are run directly, as in those tests.
#include "test_support.h"
#include "upsample_gpu_support.h"

#include "temporal/render/render.h"
#include "temporal/scene/scene.h"

#include <gtest/gtest.h>

namespace {

using namespace temporal;
using namespace temporal::upsample;

// Frames 5-12 of walkers.glb at 40 fps (each with its previous frame's state for the motion), G-buffer and shade.
const std::vector<test::SyntheticFrame>& rendered() {
  static const std::vector<test::SyntheticFrame> frames = [] {
    std::vector<test::SyntheticFrame> out;
    auto scene = Scene::load((test::source_dir() / "assets" / "scenes" / "walkers.glb").string());
    EXPECT_TRUE(scene) << scene.error().message;
    if (!scene) return out;
    RenderOptions o;
    o.width = 64;
    o.height = 48;
    o.factor = 4;
    o.payload.shadow_map_size = 256;
    o.payload.vpl_count = 64;
    o.payload.rsm_size = 32;
    o.outputs.reference = false;
    o.outputs.color = false;
    // Through EGL, like the kernels' context: with an OSMesa renderer in the process the kernels' programs failed to
    // compile (with an empty log) on this machine; the renderer's outputs are the same either way (render_egl_test).
    o.gl = GlApi::Egl;
    auto renderer = Renderer::create(o, geometry_of(*scene));
    EXPECT_TRUE(renderer) << renderer.error().message;
    if (!renderer) return out;
    const double fps = 40.0;
    FrameState previous = scene->evaluate(4 / fps);
    for (int frame = 5; frame <= 12; ++frame) {
      const FrameState current = scene->evaluate(frame / fps);
      FrameInput in;
      in.frame = frame;
      in.fps = fps;
      in.current = &current;
      in.previous = &previous;
      auto r = renderer->render(in);
      EXPECT_TRUE(r) << r.error().message;
      if (!r) return std::vector<test::SyntheticFrame>{};
      test::SyntheticFrame f;
      f.gbuffer = std::move(*r->gbuffer);
      f.low = std::move(*r->shade);
      out.push_back(std::move(f));
      previous = current;
    }
    return out;
  }();
  return frames;
}

struct Result {
  test::StateComparison states;
  double peak = 0.0;  // the largest |value| of the C++ output (the payload is HDR)
};

// The rendered frames with a cut after the fourth and the renderer's warped depth (prevDepth.Z), default options.
Result compare(const std::shared_ptr<gpu::Context>& ctx, const char* method, test::GpuStateFactory make_gpu) {
  const auto& frames = rendered();
  Result r;
  if (frames.empty()) return r;
  auto peak = [&r](const Image& cpu, const Image&) {
    for (const char* c : {"R", "G", "B"})
      for (std::size_t i = 0; i < cpu.pixel_count(); ++i) r.peak = std::max(r.peak, double(std::abs(cpu.plane(c)[i])));
  };
  test::StateSequence sequence{frames, 4, false, false};
  sequence.warped_depth_plane = "prevDepth.Z";
  r.states = test::compare_method(ctx, method, make_gpu, Options{}, sequence, {}, {}, peak);
  return r;
}

// Bounds relative to the output's peak (the payload is HDR; the synthetic tests' bounds are for values in [0, 1]),
// the same as those tests', and a PSNR over that peak; the issue's 50 dB is far below. Measured on llvmpipe
// (2026-11-26, peak 0.66): max |GPU - CPU| spatial 1.3e-7, temporal 8.9e-8, herzog 1.2e-7, taau 1.8e-7; PSNR over
// the peak 152-158 dB.
void expect_agreement(const char* method, const Result& r, double max_rel) {
  SCOPED_TRACE(method);
  ASSERT_GT(r.peak, 0.0);
  const test::StateComparison& s = r.states;
  EXPECT_LE(s.colour.max_abs / r.peak, max_rel);
  EXPECT_GE(s.colour.psnr + 20.0 * std::log10(r.peak), 125.0);  // PSNR with the peak as the signal
  EXPECT_EQ(s.colour.finiteness_mismatches, 0u);
  EXPECT_EQ(s.stat_mismatches, 0u);
  if (std::string(method) != "spatial") {
    EXPECT_GT(s.history_pixels, 0u);
    EXPECT_GT(s.misses, 0u);  // the walkers disocclude
  }
  ::testing::Test::RecordProperty(std::string("max_abs_") + method,
                                 (::testing::Message() << s.colour.max_abs << " peak " << r.peak << " psnr(peak) "
                                                       << s.colour.psnr + 20.0 * std::log10(r.peak)).GetString());
}

TEST(UpsampleGpuRendered, EveryGpuMethodMatchesItsCppMethod) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  ASSERT_EQ(rendered().size(), 8u);
  expect_agreement("spatial", compare(ctx, "spatial", make_spatial_state_gpu), 1e-6);
  expect_agreement("temporal", compare(ctx, "temporal", make_temporal_state_gpu), 1e-6);
  expect_agreement("herzog", compare(ctx, "herzog", make_herzog_state_gpu), 2e-6);
  expect_agreement("taau", compare(ctx, "taau", make_taau_state_gpu), 1e-5);
  expect_agreement("drobot", compare(ctx, "drobot", make_drobot_state_gpu), 2e-6);
}

}  // namespace
