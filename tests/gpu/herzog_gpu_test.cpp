// upsample-st's `herzog` GLSL kernels (herzog_gpu.cpp) against its C++ state (herzog.cpp, the reference of record)
// on the synthetic G-buffer sequence of the upsampling tests (a panning textured background, a foreground square
// moving over it with its own depth and id: disocclusions every frame; k = 4 regular jitter; a NaN low-resolution
// sample now and then; a cut at frame 6), for the defaults and every option that changes the kernels' arithmetic,
// and the state round trips GPU -> CPU and CPU -> GPU. The FrameContext is built as Upsampler::build_context builds it.
#include "gpu_methods.h"
#include "gpu_support.h"
#include "herzog.h"
#include "synthetic.h"
#include "upsample_context.h"
#include "temporal/gpu/timer.h"

#include <gtest/gtest.h>

#include <functional>
#include <limits>

namespace {

using namespace temporal;
using namespace temporal::upsample;
using test::build_context;
using test::geometry_of;
const std::vector<std::string> kRgb = {"R", "G", "B"};

std::vector<test::SyntheticFrame> sequence(int n, int width = 76, int height = 52) {
  test::SyntheticScene scene;
  scene.width = width;  // 76 x 52: 19 x 13 low-resolution pixels, 38 x 26 gradient cells, none a multiple of 16
  scene.height = height;
  scene.k = 4;
  scene.camera_velocity = {0.6f, -0.4f};
  scene.object = true;
  scene.object_velocity = {1.5f, 0.7f};
  std::vector<test::SyntheticFrame> frames;
  for (int t = 0; t < n; ++t) {
    frames.push_back(test::make_frame(scene, t));
    // A non-finite sample now and then: it must carry weight 0 and never enter the history.
    frames.back().low.plane("G")[std::size_t((5 * t) % 200)] = std::numeric_limits<float>::quiet_NaN();
  }
  return frames;
}

// Options with herzog's own options set by `set`.
Options options_with(const std::function<void(HerzogOptions&)>& set) {
  Options o;  // per_method holds every method's options with their defaults
  MethodOptions* m = o.per_method.find("herzog");
  EXPECT_NE(m, nullptr);
  if (m && set) set(static_cast<OptionsOf<HerzogOptions>&>(*m));
  return o;
}

std::unique_ptr<MethodState> cpu_state(const Options& o, const Geometry& g) {
  return find_implementation(*find_entry("herzog"), kCpuDevice)->make(o, g);
}

// The arithmetic that can differ (herzog_gpu.cpp's file comment): the weights' and fast_exp2's multiply-adds, which
// the driver and GCC (-march=native) may contract into FMAs differently, and eq. 7's and the luminance's sums: a few
// float ulps of a weight, normalised away in eq. 6 and eq. 7, and damped by the history (eq. 7 is a convex
// combination, so a difference never grows from frame to frame). Every decision (hit, the gradient cell, a sample's
// validity) is the same, so no pixel differs by more than rounding. Measured on llvmpipe (Mesa 22.3.6, 2026-11-26):
// see docs/gpu.md; the bounds leave a margin of about 5x over the worst variant.
constexpr double kHerzogMaxAbs = 2e-6, kHerzogPsnr = 125.0;
// The debug planes: the weights (w~, h_w, its convergence) relative to their value, the gradient and w_f absolute.
constexpr double kHerzogDebugRel = 2e-5, kHerzogDebugAbs = 2e-6;

struct Comparison {
  test::Agreement colour;
  std::size_t stat_mismatches = 0, disocclusion_mismatches = 0;
  std::size_t history_pixels = 0, misses = 0;  // the CPU's counts over the sequence (with history)
  double debug_rel = 0.0, debug_abs = 0.0;
  Image last_cpu;  // the C++ output of the last frame
};

Comparison compare(const std::shared_ptr<gpu::Context>& ctx, const Options& o, bool warped, bool debug) {
  const auto frames = sequence(10);
  const Geometry g = geometry_of(frames[0]);
  auto cpu = cpu_state(o, g);
  auto gpu = make_herzog_state_gpu(ctx, o, g);
  EXPECT_TRUE(gpu) << gpu.error().message;
  Comparison r;
  if (!gpu) return r;
  FrameContext f;
  for (int t = 0; t < int(frames.size()); ++t) {
    build_context(f, o, frames[std::size_t(t)], warped, debug);
    const bool history = t > 0 && t != 6;  // a cut at frame 6
    FrameStats sc, sg;
    const Image& a = cpu->run(f, history, sc);
    const Image& b = (*gpu)->run(f, history, sg);
    EXPECT_TRUE((*gpu)->run_status()) << (*gpu)->run_status().error().message;
    const test::Agreement ag = test::agreement(b, a, kRgb);
    r.colour.merge(ag);
    r.stat_mismatches += (sc.hole_pixels != sg.hole_pixels) + (sc.history_pixels != sg.history_pixels);
    if (history) {
      r.history_pixels += sc.history_pixels;
      r.misses += sc.hole_pixels;
    }
    if (t + 1 == int(frames.size())) r.last_cpu = a;
    if (!debug) continue;
    const float* da = a.plane("debug.disocclusion");
    const float* db = b.plane("debug.disocclusion");
    EXPECT_TRUE(da && db);
    if (da && db)
      for (std::size_t i = 0; i < a.pixel_count(); ++i) r.disocclusion_mismatches += da[i] != db[i];
    // Weights (w~ unbounded, h_w up to 2 k^2) relative to their value; the gradient and w_f (in [0, 1], a
    // difference of luminances near 0 in the relative gradient) absolute.
    for (const char* name : {"debug.confidence", "debug.historyWeight", "debug.convergence", "debug.gradient",
                             "debug.wf"}) {
      const bool relative = std::string(name) != "debug.gradient" && std::string(name) != "debug.wf";
      const float* pa = a.plane(name);
      const float* pb = b.plane(name);
      EXPECT_TRUE(pa && pb) << name;
      if (!pa || !pb) continue;
      double& worst = relative ? r.debug_rel : r.debug_abs;
      for (std::size_t i = 0; i < a.pixel_count(); ++i) {
        const double d = std::abs(double(pa[i]) - pb[i]);
        worst = std::max(worst, relative ? d / std::max(1e-6, std::abs(double(pa[i]))) : d);
      }
    }
  }
  return r;
}

void expect_agreement(const Comparison& r) {
  EXPECT_LE(r.colour.max_abs, kHerzogMaxAbs);
  EXPECT_GE(r.colour.psnr, kHerzogPsnr);
  EXPECT_EQ(r.colour.finiteness_mismatches, 0u);
  EXPECT_EQ(r.stat_mismatches, 0u);
  EXPECT_EQ(r.disocclusion_mismatches, 0u);
  EXPECT_LE(r.debug_rel, kHerzogDebugRel);
  EXPECT_LE(r.debug_abs, kHerzogDebugAbs);
  EXPECT_GT(r.history_pixels, 0u);  // the sequence reprojects history ...
  EXPECT_GT(r.misses, 0u);          // ... and has disocclusions
}

// Each variant changes what the kernels compute: the options of herzog.h, one at a time.
struct Variant {
  const char* name;
  std::function<void(HerzogOptions&)> set;
};
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
  for (bool warped : {false, true})
    for (bool debug : {false, true}) {
      SCOPED_TRACE(::testing::Message() << "warped " << warped << " debug " << debug);
      const Comparison r = compare(ctx, options_with(nullptr), warped, debug);
      expect_agreement(r);
      RecordProperty(std::string("max_abs_") + (warped ? "w" : "") + (debug ? "d" : ""),
                     (::testing::Message() << r.colour.max_abs << " psnr " << r.colour.psnr).GetString());
    }
}

TEST(HerzogGpu, MatchesTheCppMethodForEveryOption) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  Image defaults;
  for (const Variant& v : variants()) {
    SCOPED_TRACE(v.name);
    const Comparison r = compare(ctx, options_with(v.set), true, true);
    expect_agreement(r);
    // Each variant's option reaches the C++ method and changes its output (else the comparison tests nothing new).
    if (!v.set)
      defaults = r.last_cpu;
    else
      EXPECT_GT(test::agreement(r.last_cpu, defaults, kRgb).max_abs, 1e-4);
    RecordProperty(std::string("max_abs_") + v.name,
                   (::testing::Message() << r.colour.max_abs << " psnr " << r.colour.psnr << " debug rel "
                                         << r.debug_rel << " abs " << r.debug_abs).GetString());
  }
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
  const auto frames = sequence(12);
  const Geometry g = geometry_of(frames[0]);
  FrameContext f;
  FrameStats stats;
  for (bool lagged : {false, true}) {
    const Options o = options_with([lagged](HerzogOptions& h) { h.lagged_wf = lagged; });
    auto reference = cpu_state(o, g);
    Image expected;
    for (int t = 0; t < 12; ++t) {
      build_context(f, o, frames[std::size_t(t)], true, false);
      expected = reference->run(f, t > 0, stats);
    }
    for (bool gpu_first : {true, false}) {
      SCOPED_TRACE(::testing::Message() << (gpu_first ? "GPU -> CPU" : "CPU -> GPU") << " lagged " << lagged);
      auto cpu = cpu_state(o, g);
      auto gpu = make_herzog_state_gpu(ctx, o, g);
      ASSERT_TRUE(gpu) << gpu.error().message;
      MethodState& first = gpu_first ? **gpu : *cpu;
      MethodState& second = gpu_first ? *cpu : **gpu;
      for (int t = 0; t < 6; ++t) {
        build_context(f, o, frames[std::size_t(t)], true, false);
        first.run(f, t > 0, stats);
      }
      Image state(g.W, g.H);
      first.save(state);
      // The same planes whichever device wrote them.
      for (const auto& n : {"history.R", "history.G", "history.B", "history.weight", "gradient.t1", "gradient.t2",
                            "gradient.t3", "gradient.wf", "prev.depth"})
        EXPECT_TRUE(state.plane(n)) << n;
      EXPECT_TRUE(state.uint_plane("prev.id"));
      ASSERT_TRUE(second.load(state));
      Image got;
      for (int t = 6; t < 12; ++t) {
        build_context(f, o, frames[std::size_t(t)], true, false);
        got = second.run(f, true, stats);
        ASSERT_TRUE(second.run_status());
      }
      const test::Agreement a = test::agreement(got, expected, kRgb);
      EXPECT_LE(a.max_abs, kHerzogMaxAbs);
      EXPECT_GE(a.psnr, kHerzogPsnr);
      EXPECT_EQ(a.finiteness_mismatches, 0u);
      RecordProperty(std::string("round_trip_max_abs_") + (gpu_first ? "gpu_cpu" : "cpu_gpu") +
                         (lagged ? "_lagged" : ""),
                     (::testing::Message() << a.max_abs).GetString());
    }
  }
}

TEST(HerzogGpu, LoadNamesAMissingPlane) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  const auto frames = sequence(1);
  const Geometry g = geometry_of(frames[0]);
  auto gpu = make_herzog_state_gpu(ctx, options_with(nullptr), g);
  ASSERT_TRUE(gpu);
  Image state(g.W, g.H);
  for (const auto& c : kRgb) state.add_channel("history." + c);
  const Status st = (*gpu)->load(state);
  ASSERT_FALSE(st);
  EXPECT_NE(st.error().message.find("history.weight"), std::string::npos) << st.error().message;
}

// The registry's "gpu" implementation of herzog (what --device gpu picks): the same kernels on the shared context.
TEST(HerzogGpu, IsRegisteredAsTheGpuImplementation) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  const auto* implementation = find_implementation(*find_entry("herzog"), kGpuDevice);
  ASSERT_NE(implementation, nullptr);
  const auto frames = sequence(3);
  const Geometry g = geometry_of(frames[0]);
  const Options o = options_with(nullptr);
  auto gpu = implementation->make(o, g);
  auto cpu = cpu_state(o, g);
  ASSERT_TRUE(gpu && cpu);
  EXPECT_NE(dynamic_cast<gpu::TimedKernel*>(gpu.get()), nullptr);
  FrameContext f;
  FrameStats stats;
  for (int t = 0; t < 3; ++t) {
    build_context(f, o, frames[std::size_t(t)], true, false);
    const Image& a = cpu->run(f, t > 0, stats);
    const Image& b = gpu->run(f, t > 0, stats);
    ASSERT_TRUE(gpu->run_status()) << gpu->run_status().error().message;
    EXPECT_LE(test::agreement(b, a, kRgb).max_abs, kHerzogMaxAbs);
  }
}

// Every upsampling method is registered with a "gpu" implementation (what --device gpu picks), and the registered
// factory runs its kernels: three frames against the CPU implementation, within the loosest method bound (taau's).
TEST(GpuImplementation, EveryUpsampleMethodHasOne) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  const auto frames = sequence(3);
  const Geometry g = geometry_of(frames[0]);
  const Options o;
  for (const MethodEntry* e : registry()) {
    SCOPED_TRACE(e->info.name);
    const auto* gpu_impl = find_implementation(*e, kGpuDevice);
    ASSERT_NE(gpu_impl, nullptr);
    auto gpu = gpu_impl->make(o, g);
    auto cpu = find_implementation(*e, kCpuDevice)->make(o, g);
    ASSERT_TRUE(gpu && cpu);
    FrameContext f;
    FrameStats stats;
    for (int t = 0; t < 3; ++t) {
      build_context(f, o, frames[std::size_t(t)], true, false);
      const Image& a = cpu->run(f, t > 0, stats);
      const Image& b = gpu->run(f, t > 0, stats);
      ASSERT_TRUE(gpu->run_status()) << gpu->run_status().error().message;
      EXPECT_LE(test::agreement(b, a, kRgb).max_abs, 1e-5);
    }
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
