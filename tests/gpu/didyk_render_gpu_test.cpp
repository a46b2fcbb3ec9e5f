// morph-120hz's `didyk` GPU kernels against the C++ reference on a small sequence rendered by the renderer
// (tests/render/synthetic_scene.h: camera, node and vertex motion), at factor 3. In gpu_render_test, which links the
// renderer; the synthetic cases are in didyk_gpu_test.cpp (gpu_morph_test), the comparison in didyk_gpu_support.h.
#include "didyk_gpu_support.h"
#include "synthetic_scene.h"  // tests/render
#include "temporal/render/render.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace {

using namespace temporal;
using namespace temporal::test::didyk;

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

// The requirement: at least 50 dB between the GPU and the C++ outputs on a rendered sequence (3 frames,
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

}  // namespace
