// filter-phlm's GPU kernels (ema, taa) against their C++ implementations on a synthetic rendered sequence (the
// upsampling tests' G-buffer generator: a panning textured background, a moving foreground square with its own
// id and depth, full-resolution motion), with noise, NaN pixels and a reset, and the state round trips
// GPU -> CPU and CPU -> GPU. Tolerances: docs/gpu.md.
#include "gpu_support.h"
#include "synthetic.h"
#include "temporal/gpu/timer.h"
#include "temporal/phlm/ema.h"
#include "temporal/phlm/filters.h"
#include "temporal/phlm/fxaa.h"
#include "temporal/phlm/gpu_filters.h"
#include "temporal/phlm/phlm.h"
#include "temporal/phlm/taa.h"

#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <random>

namespace {

using namespace temporal;
using namespace temporal::phlm;
const std::vector<std::string> kRgb = {"R", "G", "B"};

// One frame of the test sequence: the reference colour with noise (so that the history matters), a few NaN
// pixels, and the G-buffer. Frame sizes are not multiples of the 16 x 16 work group.
struct Frame {
  Image color, gbuffer;
  glm::vec2 jitter{0.0f, 0.0f};
};

std::vector<Frame> sequence(int frames, bool camera_pan = true) {
  test::SyntheticScene scene;
  scene.width = 70;
  scene.height = 45;
  scene.k = 1;
  scene.camera_velocity = camera_pan ? glm::vec2(0.7f, -0.3f) : glm::vec2(0.0f);
  scene.object = true;
  scene.object_velocity = {1.3f, 0.6f};
  std::mt19937 rng(3);
  std::normal_distribution<float> noise(0.0f, 0.05f);
  std::vector<Frame> out;
  for (int t = 0; t < frames; ++t) {
    test::SyntheticFrame f = test::make_frame(scene, t);
    Frame fr;
    fr.color = f.reference;
    for (const auto& c : kRgb) {
      float* p = fr.color.plane(c);
      for (std::size_t i = 0; i < fr.color.pixel_count(); ++i) p[i] += noise(rng);
    }
    fr.color.plane("G")[std::size_t(7 + 3 * t)] = std::numeric_limits<float>::quiet_NaN();
    fr.color.plane("R")[std::size_t(500 + t)] = std::numeric_limits<float>::infinity();
    fr.gbuffer = std::move(f.gbuffer);
    fr.jitter = {0.25f * float((t % 4) - 1.5f), 0.2f * float((t % 3) - 1)};
    out.push_back(std::move(fr));
  }
  return out;
}

struct InputOptions {
  bool motion = true, depth = true, ids = true, warped = false, mono = false, debug = true;
  int reset_frame = -1;
};

FilterInput input_for(const Frame& f, int t, const InputOptions& o) {
  FilterInput in;
  in.color = &f.color;
  in.channels = o.mono ? std::vector<std::string>{"G"} : kRgb;
  if (o.motion) {
    in.motion_x = f.gbuffer.plane("motion.X");
    in.motion_y = f.gbuffer.plane("motion.Y");
  }
  if (o.depth) in.depth = f.gbuffer.plane("depth.Z");
  // The synthetic planes are fronto-parallel: the warped depth is the depth (exercises the warped-depth rule).
  if (o.warped) in.prev_depth = f.gbuffer.plane("depth.Z");
  if (o.ids) in.id = f.gbuffer.uint_plane("id");
  in.jitter = f.jitter;
  in.reset = t == 0 || t == o.reset_frame;
  in.debug = o.debug;
  return in;
}

// Runs both filters over frames [first, last) and returns the worst agreement of the filtered channels (with the
// values beyond 1e-5 counted); the debug planes and the counts must match exactly (they are decisions, not sums).
struct Comparison {
  test::Agreement colour;
  std::size_t debug_mismatches = 0, stat_mismatches = 0;
};

Comparison compare(FrameFilter& gpu, FrameFilter& cpu, const std::vector<Frame>& frames, int first, int last,
            const InputOptions& o, const std::vector<std::string>& debug_planes) {
  Comparison r;
  Image out_gpu, out_cpu;
  for (int t = first; t < last; ++t) {
    const FilterInput in = input_for(frames[std::size_t(t)], t, o);
    FilterStats sg, sc;
    const Status a = gpu.process(in, out_gpu, &sg);
    const Status b = cpu.process(in, out_cpu, &sc);
    EXPECT_TRUE(a) << a.error().message;
    EXPECT_TRUE(b) << b.error().message;
    if (!a || !b) return r;
    r.colour.merge(test::agreement(out_gpu, out_cpu, in.channels, 1e-5));
    if (o.debug)
      for (const auto& d : debug_planes) r.debug_mismatches += test::differing_values(out_gpu, out_cpu, d);
    r.stat_mismatches += (sg.non_finite != sc.non_finite) + (sg.history_resets != sc.history_resets) +
                         (sg.clamped != sc.clamped);
  }
  return r;
}

// The measured agreement of case `index` in the test's XML properties.
void record(const std::string& prefix, int index, const test::Agreement& a) {
  ::testing::Test::RecordProperty(prefix + "max_abs_" + std::to_string(index),
                                  (::testing::Message() << a.max_abs).GetString());
  ::testing::Test::RecordProperty(prefix + "psnr_" + std::to_string(index), std::to_string(a.psnr));
}

using Factory = std::function<Expected<std::unique_ptr<FrameFilter>>(std::shared_ptr<gpu::Context>)>;
using CpuFactory = std::function<std::unique_ptr<FrameFilter>()>;

// Runs `frames` frames uninterrupted on the CPU; and `split` frames on one device, its saved state loaded into the
// other device's filter, the rest there. Returns the worst agreement of the last frame's output.
test::Agreement round_trip(std::shared_ptr<gpu::Context> ctx, const Factory& make_gpu, const CpuFactory& make_cpu,
                           bool gpu_first, const InputOptions& o) {
  const auto frames = sequence(12);
  const int split = 6;
  auto reference = make_cpu();
  Image ref_out;
  for (int t = 0; t < int(frames.size()); ++t)
    EXPECT_TRUE(reference->process(input_for(frames[std::size_t(t)], t, o), ref_out));

  auto gpu = make_gpu(ctx);
  EXPECT_TRUE(gpu) << gpu.error().message;
  if (!gpu) return {};
  auto cpu = make_cpu();
  FrameFilter& first = gpu_first ? **gpu : *cpu;
  FrameFilter& second = gpu_first ? *cpu : **gpu;
  Image out;
  for (int t = 0; t < split; ++t) EXPECT_TRUE(first.process(input_for(frames[std::size_t(t)], t, o), out));
  const Image state = first.saved_state();
  EXPECT_FALSE(state.empty());
  const Status s = second.set_state(state, o.mono ? 1 : 3);
  EXPECT_TRUE(s) << (s ? "" : s.error().message);
  // The saved planes are the same set whichever device wrote them.
  auto cpu_names = cpu->saved_state().channel_names();
  for (int t = split; t < int(frames.size()); ++t)
    EXPECT_TRUE(second.process(input_for(frames[std::size_t(t)], t, o), out));
  const Image final_state = second.saved_state();
  EXPECT_EQ(final_state.channel_names().size(), reference->saved_state().channel_names().size());
  for (const auto& n : reference->saved_state().channel_names()) EXPECT_TRUE(final_state.has_channel(n)) << n;
  return test::agreement(out, ref_out, o.mono ? std::vector<std::string>{"G"} : kRgb);
}

// round_trip in both directions within the filter's bounds.
void expect_resumes_on_either_device(const std::shared_ptr<gpu::Context>& ctx, const Factory& make_gpu,
                                     const CpuFactory& make_cpu, double max_abs, double min_psnr) {
  for (bool gpu_first : {true, false}) {
    SCOPED_TRACE(gpu_first ? "GPU -> CPU" : "CPU -> GPU");
    test::expect_within(round_trip(ctx, make_gpu, make_cpu, gpu_first, {}), max_abs, min_psnr);
  }
}

// The input variants of the filter comparisons besides the defaults: one channel (G), no motion, a reset at frame 4.
InputOptions mono_input() {
  InputOptions o;
  o.mono = true;
  return o;
}
InputOptions no_motion_input() {
  InputOptions o;
  o.motion = false;
  return o;
}
InputOptions reset_at_frame_4() {
  InputOptions o;
  o.reset_frame = 4;
  return o;
}

// One case of a filter comparison: the GPU filter `make_gpu` makes against the C++ one over every frame (compare).
Comparison compare_case(const std::shared_ptr<gpu::Context>& ctx, const Factory& make_gpu, const CpuFactory& make_cpu,
                        const std::vector<Frame>& frames, const InputOptions& o,
                        const std::vector<std::string>& debug_planes) {
  auto gpu = make_gpu(ctx);
  EXPECT_TRUE(gpu) << gpu.error().message;
  if (!gpu) return {test::Agreement::failed()};
  return compare(**gpu, *make_cpu(), frames, 0, int(frames.size()), o, debug_planes);
}

// --- EMA -----------------------------------------------------------------------------------------------------
// The same arithmetic as ema.cpp (one multiply-add per channel after the same bilinear gather): differences are
// float rounding of FMA contraction only, and every decision (debug.reject, the counts) is equal. Measured on
// llvmpipe (2026-11-26): max |GPU - CPU| 1.2e-7 (one float ulp at 1) on values in about [-0.2, 1.2], PSNR 155 dB;
// the bound is 1e-6 and 130 dB.
constexpr double kEmaMaxAbs = 1e-6, kEmaPsnr = 130.0;

Factory ema_gpu(EmaParams p = {}) {
  return [p](std::shared_ptr<gpu::Context> c) { return make_ema_filter_gpu(std::move(c), p); };
}
CpuFactory ema_cpu(EmaParams p = {}) {
  return [p] { return std::unique_ptr<FrameFilter>(new EmaFilter(p)); };
}

TEST(EmaGpu, MatchesTheCppFilter) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  const auto frames = sequence(10);
  int case_index = 0;  // the measured agreement of each case goes to the test's XML properties
  for (const InputOptions o : {InputOptions{}, InputOptions{true, true, true, true}, InputOptions{true, false, false},
                               InputOptions{false, false, false}, InputOptions{true, true, true, false, true},
                               InputOptions{true, true, true, false, false, true, 5}}) {
    SCOPED_TRACE(::testing::Message() << "motion " << o.motion << " depth " << o.depth << " ids " << o.ids
                                      << " warped " << o.warped << " mono " << o.mono << " reset " << o.reset_frame);
    const Comparison r = compare_case(ctx, ema_gpu(), ema_cpu(), frames, o, {"debug.reject"});
    test::expect_within(r.colour, kEmaMaxAbs, kEmaPsnr);
    EXPECT_EQ(r.debug_mismatches, 0u);
    EXPECT_EQ(r.stat_mismatches, 0u);
    record("", case_index++, r.colour);
  }
}

TEST(EmaGpu, ReportsItsKernelTime) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  auto gpu = make_ema_filter_gpu(ctx);
  ASSERT_TRUE(gpu);
  const auto frames = sequence(2);
  Image out;
  for (int t = 0; t < 2; ++t) ASSERT_TRUE((*gpu)->process(input_for(frames[std::size_t(t)], t, {}), out));
  const auto* timed = dynamic_cast<const gpu::TimedKernel*>(gpu->get());
  ASSERT_NE(timed, nullptr);
  EXPECT_GT(timed->last_timing().kernel_ms, 0.0);
  EXPECT_GT(timed->last_timing().bytes_moved, 70.0 * 45 * 4 * 6);
  EXPECT_EQ(timed->last_timing().clock == gpu::Clock::GpuQuery, ctx->timer_queries());
}

TEST(EmaGpu, StateResumesOnTheCpuAndBack) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  expect_resumes_on_either_device(ctx, ema_gpu(), ema_cpu(), kEmaMaxAbs, kEmaPsnr);
}

TEST(EmaGpu, RefusesAStateWithoutHistory) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  auto gpu = make_ema_filter_gpu(ctx);
  ASSERT_TRUE(gpu);
  Image state(4, 4);
  state.add_channel("history.R");
  const Status s = (*gpu)->set_state(state, 3);
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message.find("history.G"), std::string::npos) << s.error().message;
}

// --- TAA -----------------------------------------------------------------------------------------------------
// The same arithmetic as taa.cpp with the reconstruction weights computed on the host by the same std::exp: the
// differences are float rounding (FMA contraction, and the driver's division and square root, which llvmpipe
// computes in IEEE float like the CPU). A rounding difference can flip a clip decision (t < 1) exactly at the
// box boundary; the result is continuous there, so it moves the value by rounding only. Measured on llvmpipe
// (2026-11-26): max |GPU - CPU| 3.6e-7, PSNR 148 dB; the bound is 2e-6 and 120 dB.
constexpr double kTaaMaxAbs = 2e-6, kTaaPsnr = 120.0;

Factory taa_gpu(TaaParams p = {}) {
  return [p](std::shared_ptr<gpu::Context> c) { return make_taa_filter_gpu(std::move(c), p); };
}
CpuFactory taa_cpu(TaaParams p = {}) {
  return [p] { return std::unique_ptr<FrameFilter>(new TaaFilter(p)); };
}

TEST(TaaGpu, MatchesTheCppFilter) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  const auto frames = sequence(10);
  struct Case {
    TaaParams params;
    InputOptions input;
  };
  TaaParams minmax;
  minmax.clip = "minmax";
  minmax.history = "bilinear";
  minmax.velocity = "centre";
  TaaParams nearest;
  nearest.history = "nearest";
  nearest.alpha = 0.1f;
  int case_index = 0;  // the measured agreement of each case goes to the test's XML properties
  for (const Case& c : {Case{{}, {}}, Case{minmax, {}}, Case{nearest, {}}, Case{{}, mono_input()},
                        Case{{}, no_motion_input()}, Case{minmax, reset_at_frame_4()}}) {
    SCOPED_TRACE(::testing::Message() << "clip " << c.params.clip << " history " << c.params.history << " velocity "
                                      << c.params.velocity << " mono " << c.input.mono << " motion "
                                      << c.input.motion << " reset " << c.input.reset_frame);
    const Comparison r = compare_case(ctx, taa_gpu(c.params), taa_cpu(c.params), frames, c.input,
                                      {"debug.noHistory", "debug.velocity.X", "debug.velocity.Y"});
    test::expect_within(r.colour, kTaaMaxAbs, kTaaPsnr);
    EXPECT_EQ(r.debug_mismatches, 0u);
    record("", case_index++, r.colour);
  }
}

TEST(TaaGpu, StateResumesOnTheCpuAndBack) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  expect_resumes_on_either_device(ctx, taa_gpu(), taa_cpu(), kTaaMaxAbs, kTaaPsnr);
}

TEST(TaaGpu, SameUsageErrorsAsTheCppFilter) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  TaaParams bad;
  bad.clip = "box";
  auto refused = make_taa_filter_gpu(ctx, bad);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().kind, ErrorKind::Usage);
  auto gpu = make_taa_filter_gpu(ctx);
  ASSERT_TRUE(gpu);
  const auto frames = sequence(1);
  InputOptions o;
  o.depth = false;  // nearest velocity with motion needs depth
  Image out;
  const Status s = (*gpu)->process(input_for(frames[0], 0, o), out);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().kind, ErrorKind::Usage);
}

// --- PHLM ----------------------------------------------------------------------------------------------------
// The same statements as phlm.cpp and rls.h, float rounding apart (FMA contraction in the RLS update, the
// feature and the bilinear model fetch); the RLS recursion carries those differences from frame to frame without
// growing them here, and every reset / box-test decision (debug.reset) is equal. Measured on llvmpipe
// (2026-11-26), 10 frames, 9 variants: max |GPU - CPU| 1.8e-7 (no feature) to 4.2e-6 (Catmull-Rom model fetch),
// PSNR 137-152 dB; again with the 10th (--feature-phi linear, issue 24), same day: 0 (equal) for it, at most
// 3.3e-6 (Catmull-Rom) for all. Bounds: 2e-5 and 120 dB.
constexpr double kPhlmMaxAbs = 2e-5, kPhlmPsnr = 120.0;

Factory phlm_gpu(PhlmParams p = {}) {
  return [p](std::shared_ptr<gpu::Context> c) { return make_phlm_filter_gpu(std::move(c), p); };
}
CpuFactory phlm_cpu(PhlmParams p = {}) {
  return [p] { return std::unique_ptr<FrameFilter>(new PhlmFilter(p)); };
}

TEST(PhlmGpu, MatchesTheCppFilter) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  const auto frames = sequence(10);
  struct Case {
    PhlmParams params;
    InputOptions input;
  };
  PhlmParams nearest, catmull, no_feature, no_box, eq1, phi_linear;
  nearest.model_fetch = "nearest";
  catmull.model_fetch = "catmull-rom";
  no_feature.no_feature = true;
  no_box.no_box_test = true;
  eq1.alpha_reading = "eq1";
  phi_linear.feature_phi = "linear";  // issue 24's ablation: phi = (a + b v) l
  int case_index = 0;  // the measured agreement of each case goes to the test's XML properties
  for (const Case& c : {Case{{}, {}}, Case{nearest, {}}, Case{catmull, {}}, Case{no_feature, {}}, Case{no_box, {}},
                        Case{eq1, {}}, Case{phi_linear, {}}, Case{{}, mono_input()}, Case{{}, no_motion_input()},
                        Case{{}, reset_at_frame_4()}}) {
    SCOPED_TRACE(::testing::Message() << "case " << case_index);
    const Comparison r = compare_case(ctx, phlm_gpu(c.params), phlm_cpu(c.params), frames, c.input, {"debug.reset"});
    test::expect_within(r.colour, kPhlmMaxAbs, kPhlmPsnr);
    EXPECT_EQ(r.debug_mismatches, 0u);
    record("phlm_", case_index++, r.colour);
  }
}

TEST(PhlmGpu, StateResumesOnTheCpuAndBack) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  expect_resumes_on_either_device(ctx, phlm_gpu(), phlm_cpu(), kPhlmMaxAbs, kPhlmPsnr);
}

TEST(PhlmGpu, RefusesWhatTheCppFilterRefuses) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  PhlmParams bad;
  bad.model_fetch = "cubic";
  auto refused = make_phlm_filter_gpu(ctx, bad);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().kind, ErrorKind::Usage);
  auto gpu = make_phlm_filter_gpu(ctx);
  ASSERT_TRUE(gpu);
  Image state(4, 4);
  for (const auto& n : PhlmFilter::state_channel_names(3)) state.add_channel(n, 1.0f);
  state.plane("P.D0")[5] = 0.0f;  // P not positive definite
  const Status s = (*gpu)->set_state(state, 3);
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message.find("positive definite"), std::string::npos) << s.error().message;
}

// --- FXAA ----------------------------------------------------------------------------------------------------
// The same statements as fxaa.cpp, but not the same bits: GCC (-march=native) contracts dozens of fxaa.cpp's
// multiply-adds into FMAs (the luma sum, the bilinear luma samples of the edge-end search, the subpixel terms)
// and the driver contracts its own choice of them, so a comparison in the search (|luma| >= gradient / 4, the
// span direction) can flip where it is met within a float ulp. A flip moves that pixel's final fetch (up to a
// search step along the edge), so a few pixels of a noisy frame differ visibly; the rest agree to rounding. The
// edge decisions (debug.edge) and the counts are equal. Measured on llvmpipe (2026-11-26), 4 noisy frames and a
// frame of hard 0/1 edges: RGB worst frame PSNR 56.9 dB, max |GPU - CPU| 0.057 on 2-7 of 3150 pixels per frame
// (0.1 % of the values beyond 1e-5); one channel: max 1.6e-6. Bounds: PSNR >= 50 dB on every frame (the
// issue's minimum) and at most 0.5 % of the values beyond 1e-5.
constexpr double kFxaaPsnr = 50.0, kFxaaMaxShareOver = 0.005;

TEST(FxaaGpu, MatchesTheCppFilter) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  std::vector<Frame> frames = sequence(4);
  // A frame of hard edges (a disc and diagonal steps at exactly 0 and 1): exact luma ties everywhere.
  Frame hard;
  hard.color = Image(70, 45);
  for (const auto& c : kRgb) {
    float* p = hard.color.add_channel(c);
    for (int y = 0; y < 45; ++y)
      for (int x = 0; x < 70; ++x)
        p[y * 70 + x] = ((x - 35) * (x - 35) + (y - 22) * (y - 22) < 200 || (x + 2 * y) % 17 < 5) ? 1.0f : 0.0f;
  }
  hard.gbuffer = frames[0].gbuffer;
  frames.push_back(hard);
  int case_index = 0;
  for (bool mono : {false, true}) {
    InputOptions o;
    o.mono = mono;
    auto gpu = make_fxaa_filter_gpu(ctx);
    ASSERT_TRUE(gpu) << gpu.error().message;
    FxaaFilter cpu;
    EXPECT_FALSE(find_entry("fxaa")->info.has_state);
    const Comparison r = compare(**gpu, cpu, frames, 0, int(frames.size()), o, {"debug.edge"});
    EXPECT_GE(r.colour.psnr, kFxaaPsnr);
    EXPECT_LE(r.colour.share_beyond(), kFxaaMaxShareOver);
    EXPECT_EQ(r.colour.finiteness_mismatches, 0u);
    EXPECT_EQ(r.debug_mismatches, 0u);
    EXPECT_EQ(r.stat_mismatches, 0u);
    RecordProperty("share_over_" + std::to_string(case_index), std::to_string(r.colour.share_beyond()));
    record("", case_index++, r.colour);
  }
  auto gpu = make_fxaa_filter_gpu(ctx);
  ASSERT_TRUE(gpu);
  const Status s = (*gpu)->set_state(Image(4, 4), 3);  // spatial: the CPU filter's usage error
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().kind, ErrorKind::Usage);
}

}  // namespace
