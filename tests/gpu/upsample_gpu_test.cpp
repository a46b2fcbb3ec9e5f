// upsample-st's GPU kernels (spatial, temporal) against their C++ method states on the synthetic G-buffer sequence
// of the upsampling tests (a panning textured background, a moving foreground square with its own depth and id,
// k = 4 regular jitter), with non-finite low-resolution samples, with and without the warped depth, and the state
// round trips GPU -> CPU and CPU -> GPU. The FrameContext is built as Upsampler::build_context builds it.
#include "upsample_gpu_support.h"

#include <gtest/gtest.h>

namespace {

using namespace temporal;
using namespace temporal::upsample;

// The debug plane both methods write: the joint-bilateral weight sum, relative to its value.
const std::vector<test::DebugPlaneBound> kConfidence = {{"debug.confidence", true, 1e-5, false, 1e-30}};

// 10 frames (test::upsample_gpu_sequence) with a cut at frame 6, the default options.
test::StateComparison compare(std::shared_ptr<gpu::Context> ctx, const char* method, test::GpuStateFactory make_gpu,
                              bool warped, bool debug, const std::vector<std::string>& exact_debug) {
  const auto frames = test::upsample_gpu_sequence(10);
  return test::compare_method(ctx, method, make_gpu, Options{}, {frames, 6, warped, debug}, exact_debug,
                              kConfidence);
}

// The joint-bilateral weights are products of six tri-weight factors, each 1 - x^2 / sigma^2 whose multiply-add the
// driver and GCC may contract differently: a relative weight difference of a few float ulps, normalised away in
// eq. 1. Measured on llvmpipe (2026-11-26): spatial max |GPU - CPU| 1.2e-7, temporal 1.8e-7 on payloads in about
// [0, 1]; the bounds are 1e-6 and PSNR 130 dB; every decision (computed, hit, hole) is equal.
constexpr double kUpsampleMaxAbs = 1e-6, kUpsamplePsnr = 130.0;

TEST(SpatialGpu, MatchesTheCppMethod) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  for (bool debug : {false, true}) {
    const test::StateComparison r = compare(ctx, "spatial", make_spatial_state_gpu, false, debug, {});
    test::expect_within(r.colour, kUpsampleMaxAbs, kUpsamplePsnr);
    EXPECT_EQ(r.stat_mismatches, 0u);
    EXPECT_LE(r.debug[0], kConfidence[0].bound);
    RecordProperty(debug ? "max_abs_debug" : "max_abs", (::testing::Message() << r.colour.max_abs).GetString());
  }
}

TEST(TemporalGpu, MatchesTheCppMethod) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  int case_index = 0;
  for (bool warped : {false, true})
    for (bool debug : {false, true}) {
      SCOPED_TRACE(::testing::Message() << "warped " << warped << " debug " << debug);
      const test::StateComparison r =
          compare(ctx, "temporal", make_temporal_state_gpu, warped, debug, {"debug.disocclusion"});
      test::expect_state_agreement(r, kUpsampleMaxAbs, kUpsamplePsnr, kConfidence);
      RecordProperty("max_abs_" + std::to_string(case_index++), (::testing::Message() << r.colour.max_abs).GetString());
    }
}

TEST(TemporalGpu, StateResumesOnTheCpuAndBack) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  const test::StatePlanes planes = {{"history.R", "history.G", "history.B", "prev.depth"}, "prev.id"};
  test::expect_resumes_on_either_device(ctx, "temporal", make_temporal_state_gpu, test::upsample_gpu_sequence(12),
                                        {{"", Options{}, planes}}, kUpsampleMaxAbs, kUpsamplePsnr);
}

TEST(TemporalGpu, LoadNamesAMissingPlane) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  const std::string error = test::load_error_with_only(ctx, make_temporal_state_gpu, Options{}, {"history.R"});
  EXPECT_NE(error.find("history.G"), std::string::npos) << error;
}

// The GPU histories' load (GpuHistoryState::load_history, shared by temporal, herzog, drobot-refresh and taau)
// refuses a NaN in the payload by name; the previous depth may hold anything (infinite depth is the background).
TEST(TemporalGpu, LoadRefusesANonFiniteHistory) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  const std::vector<std::string> planes = {"history.R", "history.G", "history.B", "prev.depth"};
  const std::string error = test::load_error_with_only(ctx, make_temporal_state_gpu, Options{}, planes, "history.G");
  EXPECT_NE(error.find("'history.G'"), std::string::npos) << error;
  EXPECT_NE(error.find("not finite"), std::string::npos) << error;
  EXPECT_EQ(test::load_error_with_only(ctx, make_temporal_state_gpu, Options{}, planes, "prev.depth"), "");
}

}  // namespace
