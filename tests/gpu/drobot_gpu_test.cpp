// upsample-st's `drobot` GLSL kernels (drobot_gpu.cpp) against its C++ state (drobot.cpp, the reference of record)
// on the synthetic G-buffer sequence of the upsampling tests (a panning textured background, a foreground square
// moving over it with its own depth and id: disocclusions every frame; k = 4 regular jitter; a NaN and a 1e20
// low-resolution sample every frame; a cut at frame 6), for both modes and every option that changes the kernels' arithmetic,
// and the state round trips GPU -> CPU and CPU -> GPU. The FrameContext is built as Upsampler::build_context builds it.
#include "gpu_methods.h"
#include "gpu_support.h"
#include "drobot_options.h"
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
    // ... and one past kMaxSampleMagnitude (temporal/core/image.h), which is no sample either (usable_sample).
    frames.back().low.plane("R")[std::size_t((7 * t + 101) % 200)] = 1e20f;
    // Listing 7.1's normal weight needs normals that differ (the synthetic surfaces face the camera): the right half
    // of the image tilted, a crease across which --normal-power and --depth-only change the result.
    Image& gbuf = frames.back().gbuffer;
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

// Options with herzog's own options set by `set`.
Options options_with(const std::function<void(DrobotOptions&)>& set) {
  Options o;  // per_method holds every method's options with their defaults
  MethodOptions* m = o.per_method.find("drobot");
  EXPECT_NE(m, nullptr);
  if (m && set) set(static_cast<OptionsOf<DrobotOptions>&>(*m));
  return o;
}

std::unique_ptr<MethodState> cpu_state(const Options& o, const Geometry& g) {
  return find_implementation(*find_entry("drobot"), kCpuDevice)->make(o, g);
}

// What can differ (drobot_gpu.cpp's file comment): multiply-adds contracted into FMAs differently by the driver and
// GCC (and the fast_exp2 / fast_log2 polynomials for a --normal-power other than 32): float roundings; every decision
// (cache hit, a block's validity) is the same. Measured on llvmpipe (Mesa 22.3.6, 2026-11-26): max |GPU - CPU|
// 6.6e-7 (PSNR >= 137.3 dB) over both modes and every option, round trips 4.2e-7 (before the 1e20 sample); the
// debug planes within 4.3e-7 (relative weight sum) and 1.9e-6 (frame count). Before refresh mode's fallback read 0
// at a tap that is no sample, the 1e20 sample made refresh mode differ by 1.1e12: the sample reached the output on
// both devices, and a float rounding of 1e20 is ~1e13.
constexpr double kDrobotMaxAbs = 2e-6, kDrobotPsnr = 125.0;
// The debug planes: the Listing 7.1 weight sum relative, Listing 7.2's confidence / the convergence and the frame
// count absolute.
struct DebugBound {
  const char* name;
  bool relative;
  double bound;
};
constexpr std::array<DebugBound, 3> kDebugBounds = {{{"debug.confidence", true, 2e-5},
                                                     {"debug.convergence", false, 2e-6},
                                                     {"debug.historyWeight", false, 2e-5}}};

struct Comparison {
  test::Agreement colour;
  std::size_t stat_mismatches = 0, disocclusion_mismatches = 0;
  std::size_t history_pixels = 0, misses = 0;  // the CPU's counts over the sequence (with history)
  std::array<double, 3> debug{};  // the worst difference per plane of kDebugBounds
  Image last_cpu;  // the C++ output of the last frame
};

Comparison compare(const std::shared_ptr<gpu::Context>& ctx, const Options& o, bool warped, bool debug) {
  const auto frames = sequence(10);
  const Geometry g = geometry_of(frames[0]);
  auto cpu = cpu_state(o, g);
  auto gpu = make_drobot_state_gpu(ctx, o, g);
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
    for (std::size_t d = 0; d < kDebugBounds.size(); ++d) {
      const char* name = kDebugBounds[d].name;
      const float* pa = a.plane(name);
      const float* pb = b.plane(name);
      EXPECT_EQ(pa != nullptr, pb != nullptr) << name;  // refresh mode has no debug.historyWeight
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
  EXPECT_LE(r.colour.max_abs, kDrobotMaxAbs);
  EXPECT_GE(r.colour.psnr, kDrobotPsnr);
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
  std::function<void(DrobotOptions&)> set;
};
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
  for (bool warped : {false, true})
    for (bool debug : {false, true}) {
      SCOPED_TRACE(::testing::Message() << "warped " << warped << " debug " << debug);
      const Comparison r = compare(ctx, options_with(nullptr), warped, debug);
      expect_agreement(r);
      RecordProperty(std::string("max_abs_") + (warped ? "w" : "") + (debug ? "d" : ""),
                     (::testing::Message() << r.colour.max_abs << " psnr " << r.colour.psnr).GetString());
    }
}

TEST(DrobotGpu, MatchesTheCppMethodForEveryOption) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  Image defaults;
  for (const Variant& v : variants()) {
    SCOPED_TRACE(v.name);
    const Comparison r = compare(ctx, options_with(v.set), true, true);
    expect_agreement(r);
    // Each variant's option reaches the C++ method and changes its output.
    if (!v.set) {
      defaults = r.last_cpu;
    } else {
      EXPECT_GT(test::agreement(r.last_cpu, defaults, kRgb).max_abs, 1e-4);
    }
    RecordProperty(std::string("max_abs_") + v.name,
                   (::testing::Message() << r.colour.max_abs << " psnr " << r.colour.psnr << " confidence "
                                         << r.debug[0] << " convergence " << r.debug[1] << " frames "
                                         << r.debug[2]).GetString());
  }
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
  const auto frames = sequence(12);
  const Geometry g = geometry_of(frames[0]);
  FrameContext f;
  FrameStats stats;
  for (bool lagged : {false, true}) {  // "lagged": --mode refresh here
    const Options o = options_with([lagged](DrobotOptions& h) { h.mode = lagged ? "refresh" : "cache"; });
    auto reference = cpu_state(o, g);
    Image expected;
    for (int t = 0; t < 12; ++t) {
      build_context(f, o, frames[std::size_t(t)], true, false);
      expected = reference->run(f, t > 0, stats);
    }
    for (bool gpu_first : {true, false}) {
      SCOPED_TRACE(::testing::Message() << (gpu_first ? "GPU -> CPU" : "CPU -> GPU") << " refresh " << lagged);
      auto cpu = cpu_state(o, g);
      auto gpu = make_drobot_state_gpu(ctx, o, g);
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
      const std::vector<std::string> planes =
          lagged ? std::vector<std::string>{"history.R", "history.G", "history.B", "prev.depth"}
                 : std::vector<std::string>{"cache.R", "cache.G", "cache.B", "cache.depth", "cache.frames"};
      for (const auto& n : planes) EXPECT_TRUE(state.plane(n)) << n;
      EXPECT_TRUE(state.uint_plane(lagged ? "prev.id" : "cache.id"));
      ASSERT_TRUE(second.load(state));
      Image got;
      for (int t = 6; t < 12; ++t) {
        build_context(f, o, frames[std::size_t(t)], true, false);
        got = second.run(f, true, stats);
        ASSERT_TRUE(second.run_status());
      }
      const test::Agreement a = test::agreement(got, expected, kRgb);
      EXPECT_LE(a.max_abs, kDrobotMaxAbs);
      EXPECT_GE(a.psnr, kDrobotPsnr);
      EXPECT_EQ(a.finiteness_mismatches, 0u);
      RecordProperty(std::string("round_trip_max_abs_") + (gpu_first ? "gpu_cpu" : "cpu_gpu") +
                         (lagged ? "_refresh" : "_cache"),
                     (::testing::Message() << a.max_abs).GetString());
    }
  }
}

TEST(DrobotGpu, LoadNamesAMissingPlane) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  const auto frames = sequence(1);
  const Geometry g = geometry_of(frames[0]);
  auto gpu = make_drobot_state_gpu(ctx, options_with(nullptr), g);
  ASSERT_TRUE(gpu);
  Image state(g.W, g.H);
  state.add_channel("cache.R");
  const Status st = (*gpu)->load(state);
  ASSERT_FALSE(st);
  EXPECT_NE(st.error().message.find("cache.G"), std::string::npos) << st.error().message;
}

// The registry's "gpu" implementation of herzog (what --device gpu picks): the same kernels on the shared context.
TEST(DrobotGpu, IsRegisteredAsTheGpuImplementation) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  const auto* implementation = find_implementation(*find_entry("drobot"), kGpuDevice);
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
    EXPECT_LE(test::agreement(b, a, kRgb).max_abs, kDrobotMaxAbs);
  }
}

}  // namespace
