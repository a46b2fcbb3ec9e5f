// The GPU kernels (temporal/gpu) per frame at the papers' sizes, beside the device's streaming bound: a copy kernel
// timed in the same run, and each method's bytes moved (every plane it reads or writes counted once). Implemented
// methods: filter-phlm's phlm, ema, taa and fxaa at 1920x1080 (seed 003's size; the same scene as phlm_bench: RGB
// noise on a pattern, fractional motion, depth and ids), upsample-st's spatial and temporal at 1280x1024 with k = 4,
// morph-120hz's blend, warp and didyk at 1024x1024 with factor 3 (seed 004's size).
//
// Time per iteration is the kernels' time (gpu::TimedKernel::last_timing: GL_TIME_ELAPSED on hardware, wall clock
// after glFinish on llvmpipe; the `gpu_clock` counter says which: 1 = GPU queries), not the uploads and downloads
// around them. Counters: bytes_moved (per frame), bound_ms (bytes_moved / the copy kernel's bandwidth), x_bound.
// Each benchmark is also registered at a quarter size per axis (phlm/ema/taa/fxaa /480/270,
// spatial/temporal/herzog/taau/drobot /320/256, blend/warp/didyk /256/256) for quick runs on llvmpipe:
//   gpu_benchmark --benchmark_filter='/(480|320|256)/'
// Without an EGL device every benchmark is skipped with the reason.
#include "temporal/gpu/buffer.h"
#include "temporal/gpu/glsl.h"
#include "temporal/gpu/program.h"
#include "temporal/gpu/timer.h"
#include "temporal/morph/gpu_methods.h"
#include "temporal/phlm/gpu_filters.h"
#include "upsample_context.h"
#include "gpu_methods.h"  // libtemporal/src/upsample (internal): the MethodState factories

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>
#include <random>
#include <utility>

namespace {

using namespace temporal;
using namespace temporal::phlm;
using namespace temporal::morph;

std::shared_ptr<gpu::Context> context(std::string* why) {
  static auto created = gpu::Context::create();
  if (!created) {
    *why = created.error().message;
    return nullptr;
  }
  return *created;
}

struct Scene {
  Image color, gbuffer;
  Scene(int w, int h) : color(w, h), gbuffer(w, h) {
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (const char* c : {"R", "G", "B"}) {
      float* p = color.add_channel(c);
      for (std::size_t i = 0; i < color.pixel_count(); ++i)
        p[i] = 0.5f * float((i / 7 + i / std::size_t(w) / 5) % 2) + 0.3f * u(rng);
    }
    gbuffer.add_channel("motion.X", 0.37f);
    gbuffer.add_channel("motion.Y", -0.21f);
    gbuffer.add_channel("depth.Z", 4.0f);
    gbuffer.add_uint_channel("id", 1);
  }
  FilterInput input() const {
    FilterInput in;
    in.color = &color;
    in.channels = {"R", "G", "B"};
    in.motion_x = gbuffer.plane("motion.X");
    in.motion_y = gbuffer.plane("motion.Y");
    in.depth = gbuffer.plane("depth.Z");
    in.id = gbuffer.uint_plane("id");
    in.jitter = {0.25f, -0.125f};
    return in;
  }
};

const Scene& scene(int w, int h) {
  static std::map<std::pair<int, int>, Scene> scenes;
  auto it = scenes.find({w, h});
  if (it == scenes.end()) it = scenes.emplace(std::pair{w, h}, Scene(w, h)).first;
  return it->second;
}

// The streaming bound: a kernel that copies 8 planes of w x h floats (each value read once and written once).
struct CopyKernel {
  static constexpr int kPlanes = 8;
  gpu::Program program;
  gpu::ImageBuffer a, b;
  static Expected<CopyKernel> create(const std::shared_ptr<gpu::Context>& ctx, int w, int h) {
    auto program = gpu::Program::compile(
        ctx, "copy",
        {gpu::glsl::prelude(), gpu::glsl::storage(0, "a"), gpu::glsl::storage(1, "b"),
         "uniform uint u_n;\nvoid main() { ivec2 p; uint i; if (!pixel_index(p, i)) return;\n"
         "  for (uint k = 0u; k < 8u; ++k) b[k * u_n + i] = a[k * u_n + i]; }\n"});
    if (!program) return program.error();
    auto a = gpu::ImageBuffer::create(ctx, w, h, kPlanes);
    if (!a) return a.error();
    auto b = gpu::ImageBuffer::create(ctx, w, h, kPlanes);
    if (!b) return b.error();
    if (Status s = a->clear(0, kPlanes); !s) return s.error();
    return CopyKernel{std::move(*program), std::move(*a), std::move(*b)};
  }
  double bytes() const { return 2.0 * double(a.bytes()); }
  // One copy, timed; negative on failure.
  double run_ms(gpu::Timer& timer) const {
    if (!program.use()) return -1.0;
    program.set("u_n", std::uint32_t(a.pixel_count()));
    a.bind(0);
    b.bind(1);
    timer.start();
    if (!program.dispatch(a.width(), a.height())) return -1.0;
    return timer.stop_ms();
  }
};

// The copy kernel's bandwidth in bytes per millisecond at this size: median of 5 copies after a warm-up, measured
// once per size and process (the methods' bound_ms divides their bytes by it).
double copy_bytes_per_ms(const std::shared_ptr<gpu::Context>& ctx, int w, int h) {
  static std::map<std::pair<int, int>, double> measured;
  if (auto it = measured.find({w, h}); it != measured.end()) return it->second;
  auto copy = CopyKernel::create(ctx, w, h);
  if (!copy) return 0.0;
  gpu::Timer timer(ctx);
  std::vector<double> ms;
  for (int rep = 0; rep < 6; ++rep) {
    const double t = copy->run_ms(timer);
    if (t < 0.0) return 0.0;
    if (rep > 0) ms.push_back(t);
  }
  std::sort(ms.begin(), ms.end());
  return measured[{w, h}] = copy->bytes() / ms[ms.size() / 2];
}

void BM_Copy(benchmark::State& state) {
  std::string why;
  auto ctx = context(&why);
  if (!ctx) return state.SkipWithError(("no EGL device: " + why).c_str());
  const int w = int(state.range(0)), h = int(state.range(1));
  auto copy = CopyKernel::create(ctx, w, h);
  if (!copy) return state.SkipWithError(copy.error().message.c_str());
  gpu::Timer timer(ctx);
  if (copy->run_ms(timer) < 0.0) return state.SkipWithError("the copy kernel failed");  // warm-up
  double total_ms = 0.0;
  for (auto _ : state) {
    const double ms = copy->run_ms(timer);
    if (ms < 0.0) return state.SkipWithError("the copy kernel failed");
    state.SetIterationTime(ms * 1e-3);
    total_ms += ms;
  }
  state.counters["bytes_moved"] = copy->bytes();
  state.counters["GB_per_s"] = copy->bytes() * double(state.iterations()) / (total_ms * 1e-3) / 1e9;
  state.counters["gpu_clock"] = timer.clock() == gpu::Clock::GpuQuery ? 1.0 : 0.0;
  state.SetLabel(ctx->description());
}

template <typename Make>
void run_filter(benchmark::State& state, Make make) {
  std::string why;
  auto ctx = context(&why);
  if (!ctx) return state.SkipWithError(("no EGL device: " + why).c_str());
  const int w = int(state.range(0)), h = int(state.range(1));
  auto filter = make(ctx);
  if (!filter) return state.SkipWithError(filter.error().message.c_str());
  const auto* timed = dynamic_cast<const gpu::TimedKernel*>(filter->get());
  const Scene& s = scene(w, h);
  Image out;
  // Two frames first: the first has no history (its kernel skips the fetch).
  for (int t = 0; t < 2; ++t)
    if (!(*filter)->process(s.input(), out)) return state.SkipWithError("process failed");
  for (auto _ : state) {
    if (!(*filter)->process(s.input(), out)) return state.SkipWithError("process failed");
    state.SetIterationTime(timed->last_timing().kernel_ms * 1e-3);
  }
  const gpu::KernelTiming t = timed->last_timing();
  const double rate = copy_bytes_per_ms(ctx, w, h);
  state.counters["bytes_moved"] = t.bytes_moved;
  state.counters["bound_ms"] = rate > 0.0 ? t.bytes_moved / rate : 0.0;
  state.counters["x_bound"] = rate > 0.0 ? t.kernel_ms / (t.bytes_moved / rate) : 0.0;  // last frame / bound
  state.counters["gpu_clock"] = t.clock == gpu::Clock::GpuQuery ? 1.0 : 0.0;
  state.SetLabel(ctx->description());
}

void BM_Ema(benchmark::State& state) {
  run_filter(state, [](std::shared_ptr<gpu::Context> c) { return make_ema_filter_gpu(std::move(c)); });
}
void BM_Phlm(benchmark::State& state) {
  run_filter(state, [](std::shared_ptr<gpu::Context> c) { return make_phlm_filter_gpu(std::move(c)); });
}
void BM_Fxaa(benchmark::State& state) {
  run_filter(state, [](std::shared_ptr<gpu::Context> c) { return make_fxaa_filter_gpu(std::move(c)); });
}
void BM_Taa(benchmark::State& state) {
  run_filter(state, [](std::shared_ptr<gpu::Context> c) { return make_taa_filter_gpu(std::move(c)); });
}

// Upsampling: the method state on frames of the synthetic sequence (two warm-up frames: the first has no history).
void run_upsample(benchmark::State& state, decltype(&upsample::make_spatial_state_gpu) make) {
  std::string why;
  auto ctx = context(&why);
  if (!ctx) return state.SkipWithError(("no EGL device: " + why).c_str());
  test::SyntheticScene scene;
  scene.width = int(state.range(0));
  scene.height = int(state.range(1));
  scene.k = 4;
  scene.camera_velocity = {0.6f, -0.4f};
  scene.object = true;
  scene.object_velocity = {1.5f, 0.7f};
  scene.object_size = scene.width / 4;
  std::vector<test::SyntheticFrame> frames;
  for (int t = 0; t < 4; ++t) frames.push_back(test::make_frame(scene, t));
  upsample::Options options;
  const upsample::Geometry g = test::geometry_of(frames[0]);
  auto method = make(ctx, options, g);
  if (!method) return state.SkipWithError(method.error().message.c_str());
  const auto* timed = dynamic_cast<const gpu::TimedKernel*>(method->get());
  upsample::FrameContext f;
  upsample::FrameStats stats;
  int t = 0;
  for (; t < 2; ++t) {
    test::build_context(f, options, frames[std::size_t(t)], false, false);
    (*method)->run(f, t > 0, stats);
  }
  for (auto _ : state) {
    test::build_context(f, options, frames[std::size_t(t++ % 4)], false, false);
    (*method)->run(f, true, stats);
    if (!(*method)->run_status()) return state.SkipWithError((*method)->run_status().error().message.c_str());
    state.SetIterationTime(timed->last_timing().kernel_ms * 1e-3);
  }
  const gpu::KernelTiming k = timed->last_timing();
  const double rate = copy_bytes_per_ms(ctx, g.W, g.H);
  state.counters["bytes_moved"] = k.bytes_moved;
  state.counters["bound_ms"] = rate > 0.0 ? k.bytes_moved / rate : 0.0;
  state.counters["x_bound"] = rate > 0.0 ? k.kernel_ms / (k.bytes_moved / rate) : 0.0;
  state.counters["gpu_clock"] = k.clock == gpu::Clock::GpuQuery ? 1.0 : 0.0;
  state.SetLabel(ctx->description());
}
void BM_Spatial(benchmark::State& state) { run_upsample(state, upsample::make_spatial_state_gpu); }
void BM_Temporal(benchmark::State& state) { run_upsample(state, upsample::make_temporal_state_gpu); }
void BM_Herzog(benchmark::State& state) { run_upsample(state, upsample::make_herzog_state_gpu); }
void BM_Taau(benchmark::State& state) { run_upsample(state, upsample::make_taau_state_gpu); }
void BM_Drobot(benchmark::State& state) { run_upsample(state, upsample::make_drobot_state_gpu); }

// Morphing: one rendered frame into `factor` = 3 slots; a texture moving right, a square moving the other way
// nearer the camera.
void run_morph(benchmark::State& state, decltype(&make_blend_method_gpu) make) {
  std::string why;
  auto ctx = context(&why);
  if (!ctx) return state.SkipWithError(("no EGL device: " + why).c_str());
  const int w = int(state.range(0)), h = int(state.range(1));
  Image color(w, h), next(w, h), gbuffer(w, h);
  const char* rgb[3] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c) {
    float* p = color.add_channel(rgb[c]);
    float* q = next.add_channel(rgb[c]);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        p[std::size_t(y) * w + x] = 0.35f + 0.15f * std::sin(0.45f * float(x) + 0.7f * float(c)) * std::cos(0.6f * float(y));
        q[std::size_t(y) * w + x] = 0.35f + 0.15f * std::sin(0.45f * float(x + 7) + 0.7f * float(c)) * std::cos(0.6f * float(y));
      }
  }
  float* mx = gbuffer.add_channel("motion.X");
  float* my = gbuffer.add_channel("motion.Y");
  float* d = gbuffer.add_channel("depth.Z");
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = std::size_t(y) * w + x;
      const bool square = x > w / 4 && x < w / 2 && y > h / 4 && y < h / 2;
      mx[i] = square ? 5.3f : -1.6f;
      my[i] = square ? -2.7f : 0.9f;
      d[i] = square ? 4.0f : 20.0f;
    }
  MorphOptions options;
  options.factor = 3;
  auto method = make(ctx, options);
  if (!method) return state.SkipWithError(method.error().message.c_str());
  const auto* timed = dynamic_cast<const gpu::TimedKernel*>(method->get());
  std::vector<Image> out(3, Image(w, h));
  for (auto& o : out)
    for (const char* c : rgb) o.add_channel(c);
  MorphTimings t;
  (*method)->run(color, &gbuffer, &next, out, t);  // warm-up (allocates the buffers)
  for (auto _ : state) {
    (*method)->run(color, &gbuffer, &next, out, t);
    if (!(*method)->run_status()) return state.SkipWithError((*method)->run_status().error().message.c_str());
    state.SetIterationTime(timed->last_timing().kernel_ms * 1e-3);
  }
  const gpu::KernelTiming k = timed->last_timing();
  const double rate = copy_bytes_per_ms(ctx, w, h);
  state.counters["bytes_moved"] = k.bytes_moved;
  state.counters["bound_ms"] = rate > 0.0 ? k.bytes_moved / rate : 0.0;
  state.counters["x_bound"] = rate > 0.0 ? k.kernel_ms / (k.bytes_moved / rate) : 0.0;
  state.counters["gpu_clock"] = k.clock == gpu::Clock::GpuQuery ? 1.0 : 0.0;
  // Seed 004 Table 1's split of the last frame (didyk's kernels per step; the others report morph only).
  state.counters["flow_ms"] = t.flow_ms;
  state.counters["morph_ms"] = t.morph_ms;
  state.counters["blur_ms"] = t.blur_ms;
  state.SetLabel(ctx->description());
}
void BM_Blend(benchmark::State& state) { run_morph(state, make_blend_method_gpu); }
void BM_Warp(benchmark::State& state) { run_morph(state, make_warp_method_gpu); }
// didyk (seed 004) with its defaults (8-pixel snapped grid, blur level 2, compensation): seed 004's 1024 x 1024 at
// factor 3, the size of its 5.6-7 ms for two in-between frames.
void BM_Didyk(benchmark::State& state) { run_morph(state, make_didyk_method_gpu); }

// The manual time is the kernels' time only; each iteration also uploads the inputs and reads the outputs back on
// the host. On a hardware GPU the kernels take ~0.01-0.1 ms against tens of ms of host work, so Google Benchmark's
// default (iterate until the kernels add up to min_time) runs for minutes per row. GPU_BENCH_ITERATIONS=N fixes the
// iteration count of every method row (the copy rows, which have no host work, keep the default).
void fixed_iterations(benchmark::internal::Benchmark* b) {
  if (const char* n = std::getenv("GPU_BENCH_ITERATIONS"); n && std::atoll(n) > 0) b->Iterations(std::atoll(n));
}

BENCHMARK(BM_Copy)->Args({1920, 1080})->Args({1280, 1024})->Args({1024, 1024})->Args({480, 270})->Args({320, 256})
    ->Args({256, 256})->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Ema)->Args({1920, 1080})->Args({480, 270})->Apply(fixed_iterations)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Taa)->Args({1920, 1080})->Args({480, 270})->Apply(fixed_iterations)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Phlm)->Args({1920, 1080})->Args({480, 270})->Apply(fixed_iterations)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Fxaa)->Args({1920, 1080})->Args({480, 270})->Apply(fixed_iterations)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Spatial)->Args({1280, 1024})->Args({320, 256})->Apply(fixed_iterations)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Temporal)->Args({1280, 1024})->Args({320, 256})->Apply(fixed_iterations)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Herzog)->Args({1280, 1024})->Args({320, 256})->Apply(fixed_iterations)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Taau)->Args({1280, 1024})->Args({320, 256})->Apply(fixed_iterations)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Drobot)->Args({1280, 1024})->Args({320, 256})->Apply(fixed_iterations)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Blend)->Args({1024, 1024})->Args({256, 256})->Apply(fixed_iterations)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Warp)->Args({1024, 1024})->Args({256, 256})->Apply(fixed_iterations)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Didyk)->Args({1024, 1024})->Args({256, 256})->Apply(fixed_iterations)->UseManualTime()->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
