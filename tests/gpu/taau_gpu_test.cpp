// upsample-st's `taau` GLSL kernels (taau_gpu.cpp) against its C++ state (taau.cpp, the reference of record)
// on the synthetic G-buffer sequence of the upsampling tests (a panning textured background, a foreground square
// moving over it with its own depth and id: disocclusions every frame; k = 4 regular jitter; a NaN low-resolution
// sample now and then; isolated bright samples, thin features that lock pixels; a cut at frame 6), for the defaults
// and every option that changes the kernels' arithmetic,
// and the state round trips GPU -> CPU and CPU -> GPU. The FrameContext is built as Upsampler::build_context builds it.
#include "gpu_methods.h"
#include "gpu_support.h"
#include "taau.h"
#include "synthetic.h"
#include "upsample_context.h"
#include "temporal/gpu/timer.h"

#include <gtest/gtest.h>

#include <array>
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
    // ... and one past kMaxSampleMagnitude (temporal/core/image.h), which is no sample either (issue 26 item 12).
    frames.back().low.plane("R")[std::size_t((7 * t + 101) % 200)] = 1e20f;
    // Thin features (step 5's locks): isolated bright samples, ridges no similar 2x2 quad explains, at fixed
    // low-resolution pixels, some dimming over the frames so that a lock's luminance change ends it.
    test::SyntheticFrame& fr = frames.back();
    const int lw = fr.low.width();
    for (int j = 0; j < 6; ++j) {
      const std::size_t q = std::size_t(1 + 2 * j) * lw + std::size_t(2 + 3 * j);  // inside 19 x 13
      for (const char* c : {"R", "G", "B"}) fr.low.plane(c)[q] = j < 3 ? 2.0f : 2.0f - 0.15f * float(t);
    }
  }
  return frames;
}

// Options with herzog's own options set by `set`.
Options options_with(const std::function<void(TaauOptions&)>& set) {
  Options o;  // per_method holds every method's options with their defaults
  MethodOptions* m = o.per_method.find("taau");
  EXPECT_NE(m, nullptr);
  if (m && set) set(static_cast<OptionsOf<TaauOptions>&>(*m));
  return o;
}

std::unique_ptr<MethodState> cpu_state(const Options& o, const Geometry& g) {
  return find_implementation(*find_entry("taau"), kCpuDevice)->make(o, g);
}

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
struct DebugBound {
  const char* name;
  bool relative;
  double bound;
};
constexpr std::array<DebugBound, 6> kDebugBounds = {{{"debug.confidence", true, 2e-5},
                                                     {"debug.historyWeight", true, 1e-2},
                                                     {"debug.convergence", true, 1e-2},
                                                     {"debug.gradient", false, 5e-2},
                                                     {"debug.wf", false, 2e-3},
                                                     {"debug.lock", false, 1e-5}}};

struct Comparison {
  test::Agreement colour;
  std::size_t stat_mismatches = 0, disocclusion_mismatches = 0;
  std::size_t history_pixels = 0, misses = 0;  // the CPU's counts over the sequence (with history)
  std::size_t locked_pixels = 0;  // the CPU's pixels with a live lock (debug.lock > 0) over the sequence
  std::array<double, 6> debug{};  // the worst difference per plane of kDebugBounds
  Image last_cpu;  // the C++ output of the last frame
};

Comparison compare(const std::shared_ptr<gpu::Context>& ctx, const Options& o, bool warped, bool debug) {
  const auto frames = sequence(10);
  const Geometry g = geometry_of(frames[0]);
  auto cpu = cpu_state(o, g);
  auto gpu = make_taau_state_gpu(ctx, o, g);
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
    if (const float* lock = a.plane("debug.lock"))
      for (std::size_t i = 0; i < a.pixel_count(); ++i) r.locked_pixels += lock[i] > 0.0f;
    for (std::size_t d = 0; d < kDebugBounds.size(); ++d) {
      const char* name = kDebugBounds[d].name;
      const float* pa = a.plane(name);
      const float* pb = b.plane(name);
      EXPECT_TRUE(pa && pb) << name;
      if (!pa || !pb) continue;
      for (std::size_t i = 0; i < a.pixel_count(); ++i) {
        const double diff = std::abs(double(pa[i]) - pb[i]);
        const double scaled = kDebugBounds[d].relative ? diff / std::max(1e-6, std::abs(double(pa[i]))) : diff;
        r.debug[d] = std::max(r.debug[d], scaled);
      }
    }
  }
  return r;
}

void expect_agreement(const Comparison& r) {
  EXPECT_LE(r.colour.max_abs, kTaauMaxAbs);
  EXPECT_GE(r.colour.psnr, kTaauPsnr);
  EXPECT_EQ(r.colour.finiteness_mismatches, 0u);
  EXPECT_EQ(r.stat_mismatches, 0u);
  EXPECT_EQ(r.disocclusion_mismatches, 0u);
  for (std::size_t d = 0; d < kDebugBounds.size(); ++d)
    EXPECT_LE(r.debug[d], kDebugBounds[d].bound) << kDebugBounds[d].name;
  EXPECT_GT(r.history_pixels, 0u);  // the sequence reprojects history ...
  EXPECT_GT(r.misses, 0u);          // ... and has disocclusions
}

// Each variant changes what the kernels compute: the options of herzog.h, one at a time.
struct Variant {
  const char* name;
  std::function<void(TaauOptions&)> set;
};
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
  for (bool warped : {false, true})
    for (bool debug : {false, true}) {
      SCOPED_TRACE(::testing::Message() << "warped " << warped << " debug " << debug);
      const Comparison r = compare(ctx, options_with(nullptr), warped, debug);
      expect_agreement(r);
      RecordProperty(std::string("max_abs_") + (warped ? "w" : "") + (debug ? "d" : ""),
                     (::testing::Message() << r.colour.max_abs << " psnr " << r.colour.psnr).GetString());
    }
}

TEST(TaauGpu, MatchesTheCppMethodForEveryOption) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  Image defaults;
  for (const Variant& v : variants()) {
    SCOPED_TRACE(v.name);
    const Comparison r = compare(ctx, options_with(v.set), true, true);
    expect_agreement(r);
    if (std::string(v.name) != "no-locks") {
      EXPECT_GT(r.locked_pixels, 0u);  // the thin features lock pixels
    }
    // Each variant's option reaches the C++ method and changes its output or its locks (a lock here is found again
    // only a jitter cycle later, so it never reaches the lifetime above 1 that protects a history: the colour of
    // --no-locks is the same, its debug.lock is not).
    if (!v.set) {
      defaults = r.last_cpu;
    } else {
      EXPECT_GT(test::agreement(r.last_cpu, defaults, {"R", "G", "B", "debug.lock"}).max_abs, 1e-4);
    }
    RecordProperty(std::string("max_abs_") + v.name,
                   (::testing::Message() << r.colour.max_abs << " psnr " << r.colour.psnr << " gradient "
                                         << r.debug[3] << " wf " << r.debug[4] << " weight " << r.debug[1]
                                         << " lock " << r.debug[5]).GetString());
  }
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
  const auto frames = sequence(12);
  const Geometry g = geometry_of(frames[0]);
  FrameContext f;
  FrameStats stats;
  for (bool lagged : {false, true}) {  // "lagged": --no-locks here
    const Options o = options_with([lagged](TaauOptions& h) { h.locks = !lagged; });
    auto reference = cpu_state(o, g);
    Image expected;
    for (int t = 0; t < 12; ++t) {
      build_context(f, o, frames[std::size_t(t)], true, false);
      expected = reference->run(f, t > 0, stats);
    }
    for (bool gpu_first : {true, false}) {
      SCOPED_TRACE(::testing::Message() << (gpu_first ? "GPU -> CPU" : "CPU -> GPU") << " no-locks " << lagged);
      auto cpu = cpu_state(o, g);
      auto gpu = make_taau_state_gpu(ctx, o, g);
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
      for (const auto& n : {"history.R", "history.G", "history.B", "history.weight", "lock.lifetime", "lock.luma",
                            "prev.depth"})
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
      EXPECT_LE(a.max_abs, kTaauMaxAbs);
      EXPECT_GE(a.psnr, kTaauPsnr);
      EXPECT_EQ(a.finiteness_mismatches, 0u);
      RecordProperty(std::string("round_trip_max_abs_") + (gpu_first ? "gpu_cpu" : "cpu_gpu") +
                         (lagged ? "_no_locks" : ""),
                     (::testing::Message() << a.max_abs).GetString());
    }
  }
}

TEST(TaauGpu, LoadNamesAMissingPlane) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  const auto frames = sequence(1);
  const Geometry g = geometry_of(frames[0]);
  auto gpu = make_taau_state_gpu(ctx, options_with(nullptr), g);
  ASSERT_TRUE(gpu);
  Image state(g.W, g.H);
  for (const auto& c : kRgb) state.add_channel("history." + c);
  const Status st = (*gpu)->load(state);
  ASSERT_FALSE(st);
  EXPECT_NE(st.error().message.find("history.weight"), std::string::npos) << st.error().message;
}

// The registry's "gpu" implementation of herzog (what --device gpu picks): the same kernels on the shared context.
TEST(TaauGpu, IsRegisteredAsTheGpuImplementation) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  const auto* implementation = find_implementation(*find_entry("taau"), kGpuDevice);
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
    EXPECT_LE(test::agreement(b, a, kRgb).max_abs, kTaauMaxAbs);
  }
}

}  // namespace
