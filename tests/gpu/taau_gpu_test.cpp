// upsample-st's `taau` GLSL kernels (taau_gpu.cpp) against its C++ state (taau.cpp, the reference of record)
// on the synthetic G-buffer sequence of the upsampling tests (a panning textured background, a foreground square
// moving over it with its own depth and id: disocclusions every frame; k = 4 regular jitter; a NaN low-resolution
// sample now and then; isolated bright samples, thin features that lock pixels; a cut at frame 6), for the defaults
// and every option that changes the kernels' arithmetic,
// and the state round trips GPU -> CPU and CPU -> GPU. The FrameContext is built as Upsampler::build_context builds it.
#include "taau.h"
#include "upsample_gpu_support.h"

#include <gtest/gtest.h>

#include <functional>
#include <limits>

namespace {

using namespace temporal;
using namespace temporal::upsample;

// The upsampling GPU tests' sequence (test::upsample_gpu_sequence) with samples taau must handle besides.
std::vector<test::SyntheticFrame> sequence(int n) {
  std::vector<test::SyntheticFrame> frames = test::upsample_gpu_sequence(n);
  for (int t = 0; t < n; ++t) {
    test::SyntheticFrame& fr = frames[std::size_t(t)];
    // One sample past kMaxSampleMagnitude (temporal/core/image.h), which is no sample either (issue 26 item 12).
    fr.low.plane("R")[std::size_t((7 * t + 101) % 200)] = 1e20f;
    // Thin features (step 5's locks): isolated bright samples, ridges no similar 2x2 quad explains, at fixed
    // low-resolution pixels, some dimming over the frames so that a lock's luminance change ends it.
    const int lw = fr.low.width();
    for (int j = 0; j < 6; ++j) {
      const std::size_t q = std::size_t(1 + 2 * j) * lw + std::size_t(2 + 3 * j);  // inside 19 x 13
      for (const char* c : {"R", "G", "B"}) fr.low.plane(c)[q] = j < 3 ? 2.0f : 2.0f - 0.15f * float(t);
    }
  }
  return frames;
}

// Options with taau's own options set by `set`.
Options options_with(const std::function<void(TaauOptions&)>& set) { return test::options_with("taau", set); }

// What can differ (taau_gpu.cpp's file comment): GLSL exp against std::exp in the box weights, sqrt(x^2 + y^2)
// against std::hypot in the velocity, multiply-adds contracted into FMAs differently: float roundings. Every decision
// is the same on these sequences (hit, the samples used, thin features, locks: debug.disocclusion equal, debug.lock
// within rounding). Measured on llvmpipe (Mesa 22.3.6, 2026-11-26): colour max |GPU - CPU| 2.4e-6 (PSNR 140.8 dB),
// round trips 3.2e-6; bounds 1e-5 and 125 dB.
constexpr double kTaauMaxAbs = 1e-5, kTaauPsnr = 125.0;
// The debug planes. Step 3's history weight (keep) is (|clamped - centre| + tau) / (|history - centre| + tau) with
// tau = 1e-5 of the payload's scale: a history outside the box by a rounding (1e-7) moves it by 1e-2, so the share
// of history cut (debug.gradient) and what follows from it (1 - alpha, the accumulation weight) differ far more than
// the colour, which moves by that rounding times the cut. Measured: debug.gradient 9.5e-3, debug.wf 3.5e-4, the
// accumulation 1.4e-3 relative; the lock lifetime and this frame's weight by rounding only.
const std::vector<test::DebugPlaneBound> kDebugBounds = {{"debug.confidence", true, 2e-5},
                                                         {"debug.historyWeight", true, 1e-2},
                                                         {"debug.convergence", true, 1e-2},
                                                         {"debug.gradient", false, 5e-2},
                                                         {"debug.wf", false, 2e-3},
                                                         {"debug.lock", false, 1e-5}};

struct Comparison : test::StateComparison {
  std::size_t locked_pixels = 0;  // the CPU's pixels with a live lock (debug.lock > 0) over the sequence
};

// 10 frames with a cut at frame 6; debug.disocclusion (a decision) equal value for value.
Comparison compare(const std::shared_ptr<gpu::Context>& ctx, const Options& o, bool warped, bool debug) {
  const auto frames = sequence(10);
  Comparison r;
  auto count_locks = [&r](const Image& cpu, const Image&) {
    if (const float* lock = cpu.plane("debug.lock"))
      for (std::size_t i = 0; i < cpu.pixel_count(); ++i) r.locked_pixels += lock[i] > 0.0f;
  };
  test::StateComparison& states = r;  // compare_method fills this part; count_locks the rest
  states = test::compare_method(ctx, "taau", make_taau_state_gpu, o, {frames, 6, warped, debug}, {"debug.disocclusion"},
                                kDebugBounds, count_locks);
  return r;
}

void expect_agreement(const test::StateComparison& r) {
  test::expect_state_agreement(r, kTaauMaxAbs, kTaauPsnr, kDebugBounds);
}

// Each variant changes what the kernels compute: the options of taau.h, one at a time.
using Variant = test::OptionVariant<TaauOptions>;
const std::vector<Variant>& variants() {
  static const std::vector<Variant> v = {
      {"defaults", nullptr},
      {"no-locks", [](TaauOptions& o) { o.locks = false; }},
      {"box-scale", [](TaauOptions& o) { o.box_scale = 1.5f; }},
      {"lock-luma-change", [](TaauOptions& o) { o.lock_luma_change = 0.95f; }},
      {"motion-accumulation", [](TaauOptions& o) { o.motion_accumulation = 0.1f; }},
      {"history-bilinear", [](TaauOptions& o) { o.history = "bilinear"; }},
  };
  return v;
}

TEST(TaauGpu, MatchesTheCppMethod) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  test::expect_agreement_in_every_mode(
      [&](bool warped, bool debug) { return compare(ctx, options_with(nullptr), warped, debug); }, expect_agreement);
}

TEST(TaauGpu, MatchesTheCppMethodForEveryOption) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  // Each variant's option changes the C++ method's output or its locks (a lock here is found again only a jitter
  // cycle later, so it never reaches the lifetime above 1 that protects a history: the colour of --no-locks is the
  // same, its debug.lock is not).
  test::expect_every_variant_agrees(
      "taau", variants(), [&](const Options& o) { return compare(ctx, o, true, true); },
      [](const Variant& v, const Comparison& r) {
        expect_agreement(r);
        if (std::string(v.name) != "no-locks") {
          EXPECT_GT(r.locked_pixels, 0u);  // the thin features lock pixels
        }
      },
      {"R", "G", "B", "debug.lock"},
      [](const Comparison& r) {
        return (::testing::Message() << " gradient " << r.debug[3] << " wf " << r.debug[4] << " weight "
                                     << r.debug[1] << " lock " << r.debug[5]).GetString();
      });
}

// Without ids (--no-ids) the disocclusion test is the depth test alone.
TEST(TaauGpu, MatchesTheCppMethodWithoutIds) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  Options o = options_with(nullptr);
  o.no_ids = true;
  expect_agreement(compare(ctx, o, false, true));
}

// 6 frames on one device, the state file's planes loaded into the other device's state, 6 more frames there: the
// same as 12 frames on the CPU, within the bounds above. Both directions, the defaults and --no-locks.
TEST(TaauGpu, StateResumesOnTheCpuAndBack) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  const test::StatePlanes planes = {
      {"history.R", "history.G", "history.B", "history.weight", "lock.lifetime", "lock.luma", "prev.depth"},
      "prev.id"};
  test::expect_resumes_on_either_device(
      ctx, "taau", make_taau_state_gpu, sequence(12),
      {{"", options_with(nullptr), planes},
       {"_no_locks", options_with([](TaauOptions& h) { h.locks = false; }), planes}},
      kTaauMaxAbs, kTaauPsnr);
}

TEST(TaauGpu, LoadNamesAMissingPlane) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  const std::string error = test::load_error_with_only(ctx, make_taau_state_gpu, options_with(nullptr),
                                                       {"history.R", "history.G", "history.B"});
  EXPECT_NE(error.find("history.weight"), std::string::npos) << error;
}

// The registry's "gpu" implementation of taau (what --device gpu picks): the same kernels on the shared context.
TEST(TaauGpu, IsRegisteredAsTheGpuImplementation) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  const test::RegisteredComparison r =
      test::compare_registered(*find_entry("taau"), options_with(nullptr), sequence(3));
  EXPECT_TRUE(r.timed);
  EXPECT_LE(r.colour.max_abs, kTaauMaxAbs);
}

}  // namespace
