// upsample-st's `herzog` GLSL kernels (herzog_gpu.cpp) against its C++ state (herzog.cpp, the reference of record)
// on the synthetic G-buffer sequence of the upsampling tests (a panning textured background, a foreground square
// moving over it with its own depth and id: disocclusions every frame; k = 4 regular jitter; a NaN low-resolution
// sample now and then; a cut at frame 6), for the defaults and every option that changes the kernels' arithmetic,
// and the state round trips GPU -> CPU and CPU -> GPU. The FrameContext is built as Upsampler::build_context builds it.
#include "herzog.h"
#include "upsample_gpu_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <functional>

namespace {

using namespace temporal;
using namespace temporal::upsample;
const std::vector<std::string> kRgb = {"R", "G", "B"};

std::vector<test::SyntheticFrame> sequence(int n) { return test::upsample_gpu_sequence(n); }

// Options with herzog's own options set by `set`.
Options options_with(const std::function<void(HerzogOptions&)>& set) { return test::options_with("herzog", set); }

// The arithmetic that can differ (herzog_gpu.cpp's file comment): the weights' and kernel_exp2's multiply-adds, which
// the driver and GCC (-march=native) may contract into FMAs differently, and eq. 7's and the luminance's sums: a few
// float ulps of a weight, normalised away in eq. 6 and eq. 7, and damped by the history (eq. 7 is a convex
// combination, so a difference never grows from frame to frame). Every decision (hit, the gradient cell, a sample's
// validity) is the same, so no pixel differs by more than rounding. Measured on llvmpipe (Mesa 22.3.6, 2026-11-26):
// see docs/gpu.md; the bounds leave a margin of about 5x over the worst variant.
constexpr double kHerzogMaxAbs = 2e-6, kHerzogPsnr = 125.0;
// The debug planes: the weights (w~ unbounded, h_w up to 2 k^2, its convergence) relative to their value; the
// gradient and w_f (in [0, 1], a difference of luminances near 0 in the relative gradient) absolute.
constexpr double kHerzogDebugRel = 2e-5, kHerzogDebugAbs = 2e-6;
const std::vector<test::DebugPlaneBound> kDebugBounds = {{"debug.confidence", true, kHerzogDebugRel},
                                                         {"debug.historyWeight", true, kHerzogDebugRel},
                                                         {"debug.convergence", true, kHerzogDebugRel},
                                                         {"debug.gradient", false, kHerzogDebugAbs},
                                                         {"debug.wf", false, kHerzogDebugAbs}};

// 10 frames with a cut at frame 6; debug.disocclusion (a decision) equal value for value.
test::StateComparison compare(const std::shared_ptr<gpu::Context>& ctx, const Options& o, bool warped, bool debug) {
  const auto frames = sequence(10);
  return test::compare_method(ctx, "herzog", make_herzog_state_gpu, o, {frames, 6, warped, debug},
                              {"debug.disocclusion"}, kDebugBounds);
}

void expect_agreement(const test::StateComparison& r) {
  test::expect_state_agreement(r, kHerzogMaxAbs, kHerzogPsnr, kDebugBounds);
}

// Each variant changes what the kernels compute: the options of herzog.h, one at a time.
using Variant = test::OptionVariant<HerzogOptions>;
const std::vector<Variant>& variants() {
  static const std::vector<Variant> v = {
      {"defaults", nullptr},
      {"lagged-wf", [](HerzogOptions& h) { h.lagged_wf = true; }},
      {"fallback-flat", [](HerzogOptions& h) { h.fallback = "flat"; }},
      {"favor-spatial", [](HerzogOptions& h) { h.favor_spatial = true; }},
      {"gradient-scale-1", [](HerzogOptions& h) { h.gradient_scale = 1; }},
      {"gradient-scale-4-mip-3", [](HerzogOptions& h) {  // one sampled level (frac 0)
         h.gradient_scale = 4;
         h.gradient_mip_level = 3.0f;
       }},
      {"mip-0", [](HerzogOptions& h) { h.gradient_mip_level = 0.0f; }},  // no pyramid above the grid
      {"gradient-filter-none", [](HerzogOptions& h) { h.gradient_filter = "none"; }},
      {"fixed-wf", [](HerzogOptions& h) { h.fixed_wf = 0.5f; }},
      {"gammas", [](HerzogOptions& h) {
         h.kernel_gamma = 2.5f;
         h.max_kernel_gamma = 3.0f;
         h.min_kernel_gamma = 0.5f;
       }},
      {"max-history-weight", [](HerzogOptions& h) { h.max_history_weight = 0.5f; }},
  };
  return v;
}

TEST(HerzogGpu, MatchesTheCppMethod) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  test::expect_agreement_in_every_mode(
      [&](bool warped, bool debug) { return compare(ctx, options_with(nullptr), warped, debug); }, expect_agreement);
}

TEST(HerzogGpu, MatchesTheCppMethodForEveryOption) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  test::expect_every_variant_agrees(
      "herzog", variants(), [&](const Options& o) { return compare(ctx, o, true, true); },
      [](const Variant&, const test::StateComparison& r) { expect_agreement(r); }, kRgb,
      [](const test::StateComparison& r) {
        return (::testing::Message() << " debug rel " << std::max({r.debug[0], r.debug[1], r.debug[2]}) << " abs "
                                     << std::max(r.debug[3], r.debug[4])).GetString();
      });
}

// Without ids (--no-ids) the disocclusion test is the depth test alone.
TEST(HerzogGpu, MatchesTheCppMethodWithoutIds) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  Options o = options_with(nullptr);
  o.no_ids = true;
  expect_agreement(compare(ctx, o, false, true));
}

// 6 frames on one device, the state file's planes loaded into the other device's state, 6 more frames there: the
// same as 12 frames on the CPU, within the bounds above. Both directions, the defaults and --lagged-wf.
TEST(HerzogGpu, StateResumesOnTheCpuAndBack) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  const test::StatePlanes planes = {{"history.R", "history.G", "history.B", "history.weight", "gradient.t1",
                                     "gradient.t2", "gradient.t3", "gradient.wf", "prev.depth"},
                                    "prev.id"};
  test::expect_resumes_on_either_device(
      ctx, "herzog", make_herzog_state_gpu, sequence(12),
      {{"", options_with(nullptr), planes},
       {"_lagged", options_with([](HerzogOptions& h) { h.lagged_wf = true; }), planes}},
      kHerzogMaxAbs, kHerzogPsnr);
}

TEST(HerzogGpu, LoadNamesAMissingPlane) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  const std::string error = test::load_error_with_only(ctx, make_herzog_state_gpu, options_with(nullptr),
                                                       {"history.R", "history.G", "history.B"});
  EXPECT_NE(error.find("history.weight"), std::string::npos) << error;
}

// The registry's "gpu" implementation of herzog (what --device gpu picks): the same kernels on the shared context.
TEST(HerzogGpu, IsRegisteredAsTheGpuImplementation) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  const test::RegisteredComparison r =
      test::compare_registered(*find_entry("herzog"), options_with(nullptr), sequence(3));
  EXPECT_TRUE(r.timed);
  EXPECT_LE(r.colour.max_abs, kHerzogMaxAbs);
}

// Every upsampling method is registered with a "gpu" implementation (what --device gpu picks), and the registered
// factory runs its kernels: three frames against the CPU implementation, within the loosest method bound (taau's).
TEST(GpuImplementation, EveryUpsampleMethodHasOne) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  const auto frames = sequence(3);
  for (const MethodEntry* e : registry()) {
    SCOPED_TRACE(e->info.name);
    EXPECT_LE(test::compare_registered(*e, Options{}, frames).colour.max_abs, 1e-5);
  }
}

// A GPU factory that failed (no EGL device, a kernel that does not compile) leaves a state that says so.
TEST(GpuImplementation, AFailedFactoryReportsItsError) {
  auto state = state_or_failure(Error::usage("no EGL device"));
  ASSERT_NE(state, nullptr);
  EXPECT_FALSE(state->run_status());
  EXPECT_EQ(state->run_status().error().message, "no EGL device");
  const Status loaded = state->load(Image(4, 4));
  ASSERT_FALSE(loaded);
  EXPECT_EQ(loaded.error().message, "no EGL device");
}

}  // namespace
