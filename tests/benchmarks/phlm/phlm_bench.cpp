// filter-phlm's methods at 1920x1080 (RGB, 1 spp noise, fractional motion so that the history fetches
// interpolate; the G-buffer has depth, so TAA's nearest-depth velocity reads its 3x3 depths), next to the streaming
// bound of PHLM's state traffic: a memcpy of the bytes the filter must
// read and write per frame (26 floats of models read at p + motion and 26 written, per pixel).
// BM_PhlmTaaInterleaved: phlm / taa from interleaved frames of the two (the ratio the docs quote).
// Run: build/<dir>/tests/benchmarks/phlm/phlm_bench [--benchmark_filter=...]
#include "temporal/phlm/ema.h"
#include "temporal/phlm/fxaa.h"
#include "temporal/core/parallel.h"
#include "temporal/phlm/phlm.h"
#include "temporal/phlm/taa.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

namespace {

using namespace temporal;
using namespace temporal::phlm;
constexpr int kW = 1920, kH = 1080;

struct Scene {
  Image color{kW, kH}, gbuffer{kW, kH};
  Scene() {
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (const char* c : {"R", "G", "B"}) {
      float* p = color.add_channel(c);
      for (std::size_t i = 0; i < color.pixel_count(); ++i) p[i] = 0.5f * float((i / 7 + i / kW / 5) % 2) + 0.3f * u(rng);
    }
    gbuffer.add_channel("motion.X", 0.37f);
    gbuffer.add_channel("motion.Y", -0.21f);
    gbuffer.add_channel("depth.Z", 4.0f);
    gbuffer.add_uint_channel("id", 1);
  }
  FilterInput input(bool with_motion) const {
    FilterInput in;
    in.color = &color;
    in.channels = {"R", "G", "B"};
    if (with_motion) {
      in.motion_x = gbuffer.plane("motion.X");
      in.motion_y = gbuffer.plane("motion.Y");
      in.depth = gbuffer.plane("depth.Z");
      in.id = gbuffer.uint_plane("id");
    }
    in.jitter = {0.25f, -0.125f};
    return in;
  }
};

const Scene& scene() {
  static const Scene s;
  return s;
}

template <typename Filter, typename Params>
void run_filter(benchmark::State& state, const Params& params) {
  ThreadLimit limit(int(state.range(1)));
  Filter filter(params);
  Image out;
  const FilterInput in = scene().input(state.range(0) != 0);
  (void)filter.process(in, out);  // first frame: allocations and resets
  for (auto _ : state) {
    (void)filter.process(in, out);
    benchmark::DoNotOptimize(out.plane("R"));
  }
  state.SetItemsProcessed(state.iterations() * int64_t(kW) * kH);
}

void BM_Phlm(benchmark::State& s) { run_filter<PhlmFilter>(s, PhlmParams{}); }
// PHLM with the Catmull-Rom model fetch (beta and the feature from 16 records).
void BM_PhlmCatmullRom(benchmark::State& s) {
  PhlmParams p;
  p.model_fetch = "catmull-rom";
  run_filter<PhlmFilter>(s, p);
}
// The engine-strength TAA (defaults: nearest-depth velocity, Catmull-Rom history, variance clipping) and the TAA
// this suite had before issue 16 (pixel's own motion, min/max clipping, alpha 0.04): the cost of the strengthening.
void BM_Taa(benchmark::State& s) { run_filter<TaaFilter>(s, TaaParams{}); }
void BM_Taa2014(benchmark::State& s) {
  TaaParams p;
  p.velocity = "centre";
  p.clip = "minmax";
  p.alpha = 0.04f;
  run_filter<TaaFilter>(s, p);
}
void BM_Ema(benchmark::State& s) { run_filter<EmaFilter>(s, EmaParams{}); }

void BM_Fxaa(benchmark::State& state) {
  ThreadLimit limit(int(state.range(0)));
  Image out;
  const FilterInput in = scene().input(false);
  for (auto _ : state) {
    (void)fxaa(in, out);
    benchmark::DoNotOptimize(out.plane("R"));
  }
}

// phlm / taa from interleaved frames: each iteration filters one frame with the engine TAA, then one with PHLM, each
// timed on its own, so that the host's drift (20-40 % between runs on the shared VMs) moves both times together
// instead of the ratio of two benchmarks run seconds apart. The iteration time is PHLM's frame; counter x_taa is
// phlm / taa over all iterations, taa_ms TAA's frame.
void BM_PhlmTaaInterleaved(benchmark::State& state) {
  ThreadLimit limit(int(state.range(0)));
  PhlmFilter phlm{PhlmParams{}};
  TaaFilter taa{TaaParams{}};
  Image out_phlm, out_taa;
  const FilterInput in = scene().input(true);
  (void)phlm.process(in, out_phlm);  // first frames: allocations and resets
  (void)taa.process(in, out_taa);
  using Clock = std::chrono::steady_clock;
  auto seconds = [](Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); };
  double t_phlm = 0.0, t_taa = 0.0;
  for (auto _ : state) {
    const auto c0 = Clock::now();
    (void)taa.process(in, out_taa);
    const auto c1 = Clock::now();
    (void)phlm.process(in, out_phlm);
    const auto c2 = Clock::now();
    benchmark::DoNotOptimize(out_taa.plane("R"));
    benchmark::DoNotOptimize(out_phlm.plane("R"));
    t_taa += seconds(c0, c1);
    t_phlm += seconds(c1, c2);
    state.SetIterationTime(seconds(c1, c2));
  }
  state.counters["x_taa"] = t_taa > 0.0 ? t_phlm / t_taa : 0.0;
  const double it = double(std::max<benchmark::IterationCount>(1, state.iterations()));
  state.counters["taa_ms"] = t_taa / it * 1e3;
  state.SetLabel("phlm interleaved with taa");
}

// The streaming bound: copy the bytes of one frame's PHLM state (read + write), in parallel bands like the
// filter. Nothing the filter does per frame can take less than this on the same memory system.
void BM_PhlmStateStreamBound(benchmark::State& state) {
  ThreadLimit limit(int(state.range(0)));
  const std::size_t bytes = std::size_t(kW) * kH * std::size_t(phlm_state_floats(3)) * sizeof(float);
  PlaneVector<char> src(bytes, 1), dst(bytes, 0);  // the pages the filter's planes get (allocate_plane_memory)
  for (auto _ : state) {
    parallel_rows(kH, [&](int y0, int y1) {
      const std::size_t row = bytes / kH;
      std::memcpy(dst.data() + std::size_t(y0) * row, src.data() + std::size_t(y0) * row, std::size_t(y1 - y0) * row);
    });
    benchmark::DoNotOptimize(dst.data());
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(state.iterations() * int64_t(bytes) * 2);
}

}  // namespace

// Args: motion (1: a G-buffer with fractional motion, bilinear / Catmull-Rom history fetches; 0: static
// scene), threads (0: every core; 1: one thread, whose time is meaningful on a loaded machine).
// PHLM_BENCH_ITERATIONS=N fixes every benchmark's iteration count: tests/benchmarks/port_floor.py runs a filter
// under callgrind with two counts and takes the difference (frames in the steady state, without the set-up).
int main(int argc, char** argv) {
  const char* fixed = std::getenv("PHLM_BENCH_ITERATIONS");
  const benchmark::IterationCount n = fixed ? std::atoll(fixed) : 0;
  auto ms = [&](benchmark::internal::Benchmark* b) {
    b->Unit(benchmark::kMillisecond)->UseRealTime();
    if (n > 0) b->Iterations(n);
    return b;
  };
  const std::vector<std::string> motion_threads = {"motion", "threads"};
  ms(benchmark::RegisterBenchmark("BM_Phlm", BM_Phlm))->ArgNames(motion_threads)->Args({1, 0})->Args({0, 0})->Args({1, 1});
  ms(benchmark::RegisterBenchmark("BM_PhlmCatmullRom", BM_PhlmCatmullRom))->ArgNames(motion_threads)->Args({1, 0})->Args({1, 1});
  ms(benchmark::RegisterBenchmark("BM_Taa", BM_Taa))->ArgNames(motion_threads)->Args({1, 0})->Args({0, 0})->Args({1, 1});
  ms(benchmark::RegisterBenchmark("BM_Taa2014", BM_Taa2014))->ArgNames(motion_threads)->Args({1, 0})->Args({1, 1});
  ms(benchmark::RegisterBenchmark("BM_Ema", BM_Ema))->ArgNames(motion_threads)->Args({1, 0})->Args({1, 1});
  ms(benchmark::RegisterBenchmark("BM_Fxaa", BM_Fxaa))->ArgNames({"threads"})->Arg(0)->Arg(1);
  ms(benchmark::RegisterBenchmark("BM_PhlmStateStreamBound", BM_PhlmStateStreamBound))->ArgNames({"threads"})->Arg(0)->Arg(1);
  auto* interleaved = benchmark::RegisterBenchmark("BM_PhlmTaaInterleaved", BM_PhlmTaaInterleaved);
  interleaved->ArgNames({"threads"})->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseManualTime();
  if (n > 0) interleaved->Iterations(n);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
