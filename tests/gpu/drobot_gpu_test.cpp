// upsample-st's `drobot` GLSL kernels (drobot_gpu.cpp) against its C++ state (drobot.cpp, the reference of record)
// on the synthetic G-buffer sequence of the upsampling tests (a panning textured background, a foreground square
// moving over it with its own depth and id: disocclusions every frame; k = 4 regular jitter; a NaN and a 1e20
// low-resolution sample every frame; a cut at frame 6), for both modes and every option that changes the kernels' arithmetic,
// and the state round trips GPU -> CPU and CPU -> GPU. The FrameContext is built as Upsampler::build_context builds it.
#include "drobot_options.h"
#include "upsample_gpu_support.h"

#include <gtest/gtest.h>

#include <functional>

namespace {

using namespace temporal;
using namespace temporal::upsample;
const std::vector<std::string> kRgb = {"R", "G", "B"};

// The upsampling GPU tests' sequence (test::upsample_gpu_sequence) with a sample drobot must refuse and normals that
// differ.
std::vector<test::SyntheticFrame> sequence(int n) {
  std::vector<test::SyntheticFrame> frames = test::upsample_gpu_sequence(n);
  for (int t = 0; t < n; ++t) {
    // One sample past kMaxSampleMagnitude (temporal/core/image.h), which is no sample either (usable_sample).
    frames[std::size_t(t)].low.plane("R")[std::size_t((7 * t + 101) % 200)] = 1e20f;
    // Listing 7.1's normal weight needs normals that differ (the synthetic surfaces face the camera): the right half
    // of the image tilted, a crease across which --normal-power and --depth-only change the result.
    Image& gbuf = frames[std::size_t(t)].gbuffer;
    const int width = gbuf.width(), height = gbuf.height();
    for (int y = 0; y < height; ++y)
      for (int x = width / 2; x < width; ++x) {
        const std::size_t i = std::size_t(y) * width + x;
        gbuf.plane("N.X")[i] = 0.6f;
        gbuf.plane("N.Y")[i] = 0.0f;
        gbuf.plane("N.Z")[i] = 0.8f;
      }
  }
  return frames;
}

// Options with drobot's own options set by `set`.
Options options_with(const std::function<void(DrobotOptions&)>& set) { return test::options_with("drobot", set); }

// What can differ (drobot_gpu.cpp's file comment): multiply-adds contracted into FMAs differently by the driver and
// GCC (and the fast_exp2 / fast_log2 polynomials for a --normal-power other than 32): float roundings; every decision
// (cache hit, a block's validity) is the same. Measured on llvmpipe (Mesa 22.3.6, 2026-11-26): max |GPU - CPU|
// 6.6e-7 (PSNR >= 137.3 dB) over both modes and every option, round trips 3.6e-7 (re-measured with the 1e20 sample,
// 2026-11-26); the debug planes within 4.3e-7 (relative weight sum) and 1.9e-6 (frame count). Before refresh mode's
// fallback read 0 at a tap that is no sample, the 1e20 sample made refresh mode differ by 1.1e12: the sample reached
// the output on both devices, and a float rounding of 1e20 is ~1e13.
constexpr double kDrobotMaxAbs = 2e-6, kDrobotPsnr = 125.0;
// The debug planes: the Listing 7.1 weight sum relative, Listing 7.2's confidence / the convergence and the frame
// count absolute.
const std::vector<test::DebugPlaneBound> kDebugBounds = {
    {"debug.confidence", true, 2e-5},
    {"debug.convergence", false, 2e-6},
    {"debug.historyWeight", false, 2e-5, true}};  // refresh mode has no debug.historyWeight

// 10 frames with a cut at frame 6; debug.disocclusion (a decision) equal value for value.
test::StateComparison compare(const std::shared_ptr<gpu::Context>& ctx, const Options& o, bool warped, bool debug) {
  const auto frames = sequence(10);
  return test::compare_method(ctx, "drobot", make_drobot_state_gpu, o, {frames, 6, warped, debug},
                              {"debug.disocclusion"}, kDebugBounds);
}

void expect_agreement(const test::StateComparison& r) {
  test::expect_state_agreement(r, kDrobotMaxAbs, kDrobotPsnr, kDebugBounds);
}

// Each variant changes what the kernels compute: the options of drobot_options.h, one at a time.
using Variant = test::OptionVariant<DrobotOptions>;
const std::vector<Variant>& variants() {
  static const std::vector<Variant> v = {
      {"defaults", nullptr},
      {"refresh", [](DrobotOptions& o) { o.mode = "refresh"; }},
      {"refresh-power-16", [](DrobotOptions& o) {
         o.mode = "refresh";
         o.normal_power = 16.0f;
       }},
      {"normal-power-16", [](DrobotOptions& o) { o.normal_power = 16.0f; }},
      {"depth-only", [](DrobotOptions& o) { o.depth_only = true; }},
      {"cache-point", [](DrobotOptions& o) { o.cache_point = true; }},
      {"max-frames", [](DrobotOptions& o) { o.max_frames = 4.0f; }},
      {"miss-threshold", [](DrobotOptions& o) { o.miss_threshold = 0.2f; }},
      {"convergence-time", [](DrobotOptions& o) { o.convergence_time = 5.0f; }},
      {"filter-amp", [](DrobotOptions& o) { o.filter_amp = 20.0f; }},
  };
  return v;
}

TEST(DrobotGpu, MatchesTheCppMethod) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  test::expect_agreement_in_every_mode(
      [&](bool warped, bool debug) { return compare(ctx, options_with(nullptr), warped, debug); }, expect_agreement);
}

TEST(DrobotGpu, MatchesTheCppMethodForEveryOption) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  test::expect_every_variant_agrees(
      "drobot", variants(), [&](const Options& o) { return compare(ctx, o, true, true); },
      [](const Variant&, const test::StateComparison& r) { expect_agreement(r); }, kRgb,
      [](const test::StateComparison& r) {
        return (::testing::Message() << " confidence " << r.debug[0] << " convergence " << r.debug[1] << " frames "
                                     << r.debug[2]).GetString();
      });
}

// Without ids (--no-ids) the disocclusion test is the depth test alone.
TEST(DrobotGpu, MatchesTheCppMethodWithoutIds) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  Options o = options_with(nullptr);
  o.no_ids = true;
  expect_agreement(compare(ctx, o, false, true));
}

// 6 frames on one device, the state file's planes loaded into the other device's state, 6 more frames there: the
// same as 12 frames on the CPU, within the bounds above. Both directions, both modes.
TEST(DrobotGpu, StateResumesOnTheCpuAndBack) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  test::expect_resumes_on_either_device(
      ctx, "drobot", make_drobot_state_gpu, sequence(12),
      {{"_cache", options_with([](DrobotOptions& h) { h.mode = "cache"; }),
        {{"cache.R", "cache.G", "cache.B", "cache.depth", "cache.frames"}, "cache.id"}},
       {"_refresh", options_with([](DrobotOptions& h) { h.mode = "refresh"; }),
        {{"history.R", "history.G", "history.B", "prev.depth"}, "prev.id"}}},
      kDrobotMaxAbs, kDrobotPsnr);
}

TEST(DrobotGpu, LoadNamesAMissingPlane) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  const std::string error = test::load_error_with_only(ctx, make_drobot_state_gpu, options_with(nullptr), {"cache.R"});
  EXPECT_NE(error.find("cache.G"), std::string::npos) << error;
}

// Cache mode's payload and frame counts must be finite (as drobot.cpp's load); its depth may be anything.
TEST(DrobotGpu, LoadRefusesANonFiniteCache) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  const std::vector<std::string> planes = {"cache.R", "cache.G", "cache.B", "cache.depth", "cache.frames"};
  for (const char* damaged : {"cache.B", "cache.frames"}) {
    const std::string error = test::load_error_with_only(ctx, make_drobot_state_gpu, options_with(nullptr), planes,
                                                        damaged);
    EXPECT_NE(error.find("'" + std::string(damaged) + "'"), std::string::npos) << error;
  }
  EXPECT_EQ(test::load_error_with_only(ctx, make_drobot_state_gpu, options_with(nullptr), planes, "cache.depth"), "");
}

// The registry's "gpu" implementation of drobot (what --device gpu picks): the same kernels on the shared context.
TEST(DrobotGpu, IsRegisteredAsTheGpuImplementation) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  const test::RegisteredComparison r =
      test::compare_registered(*find_entry("drobot"), options_with(nullptr), sequence(3));
  EXPECT_TRUE(r.timed);
  EXPECT_LE(r.colour.max_abs, kDrobotMaxAbs);
}

}  // namespace
