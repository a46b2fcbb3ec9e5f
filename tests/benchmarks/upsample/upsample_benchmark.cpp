// ms per frame of each upsampling method and named variant of the method table (temporal/upsample/methods.h) at
// 1280x1024 (factor 4, R,G,B payload) and, in the same run, the
// time to stream the bytes the method must read and write (Upsampler::streamed_bytes: G-buffer planes,
// payload in and out, full-resolution histories read and written once), measured as a parallel memcpy
// moving that many bytes (half read, half written). Targets (issue 4): herzog <= 1.5x spatial, and within
// 2.5x of its streaming bound.
#include "synthetic.h"
#include "upsample_variants.h"

#include "temporal/core/parallel.h"
#include "temporal/upsample/methods.h"
#include "temporal/upsample/upsample.h"

#include <benchmark/benchmark.h>

#include <cstdlib>
#include <cstring>
#include <memory>
#include <vector>

namespace up = temporal::upsample;
using temporal::Image;

namespace {

constexpr int kW = 1280, kH = 1024, kK = 4;
const std::vector<std::string> kRGB = {"R", "G", "B"};

// A camera pan over a textured plane with a square standing still on screen: one G-buffer serves every
// frame, the payload changes with the pan and the jitter. 16 frames, cycled.
struct Inputs {
  Image gbuffer;
  std::vector<Image> low;
  explicit Inputs(int scale = 1) {
    temporal::test::SyntheticScene scene;
    scene.width = kW / scale;
    scene.height = kH / scale;
    scene.k = kK;
    scene.period = 37.0f;
    scene.camera_velocity = {1.25f, 0.5f};
    scene.object = true;
    scene.object_start = {400.0f, 300.0f};
    scene.object_size = 300;
    for (int t = 1; t <= kK * kK; ++t) {
      auto f = temporal::test::make_frame(scene, t);
      if (t == 1) gbuffer = std::move(f.gbuffer);
      low.push_back(std::move(f.low));
    }
  }
};

const Inputs& inputs() {
  static const Inputs in;
  return in;
}
// The same scene at a quarter of the size per axis: every buffer a method touches (about 7 MB for herzog)
// stays in the 32 MB L3 cache.
const Inputs& small_inputs() {
  static const Inputs in(4);
  return in;
}

// Benchmark argument m: variant m of the method table.
const up::MethodVariant& variant(int m) { return up::method_variants()[std::size_t(m)]; }
up::Options options(int m) { return temporal::test::upsample_variant(variant(m).name); }
const char* name(int m) { return variant(m).name.c_str(); }
int variant_index(const char* n) {
  const auto& all = up::method_variants();
  for (std::size_t i = 0; i < all.size(); ++i)
    if (all[i].name == n) return int(i);
  return 0;
}

void BM_Upsample(benchmark::State& state) {
  const int m = int(state.range(0));
  const Inputs& in = inputs();
  up::Upsampler u(options(m));
  std::size_t t = 0;
  for (int i = 0; i < 2 * kK * kK; ++i)  // warm the histories and buffers
    (void)u.process(in.gbuffer, in.low[t++ % in.low.size()], kRGB, false);
  for (auto _ : state) {
    auto r = u.process(in.gbuffer, in.low[t++ % in.low.size()], kRGB, false);
    benchmark::DoNotOptimize(r);
  }
  state.SetLabel(name(m));
  const std::size_t bytes = up::Upsampler::streamed_bytes(options(m), kW, kH, kK, 3);
  state.counters["MB"] = double(bytes) / 1e6;
}

// Time per full-resolution pixel on one thread, at the full size (range(1) = 1) and at the L3-resident quarter
// size (range(1) = 4): equal rates mean the method is bound by its arithmetic, not by memory traffic.
void BM_PerPixel(benchmark::State& state) {
  const int m = int(state.range(0)), scale = int(state.range(1));
  const Inputs& in = scale == 1 ? inputs() : small_inputs();
  temporal::ThreadLimit one(1);
  up::Upsampler u(options(m));
  std::size_t t = 0;
  for (int i = 0; i < 2 * kK * kK; ++i) (void)u.process(in.gbuffer, in.low[t++ % in.low.size()], kRGB, false);
  for (auto _ : state) {
    auto r = u.process(in.gbuffer, in.low[t++ % in.low.size()], kRGB, false);
    benchmark::DoNotOptimize(r);
  }
  state.SetLabel(std::string(name(m)) + (scale == 1 ? " full size, 1 thread" : " L3-resident size, 1 thread"));
  const double pixels = double(in.gbuffer.width()) * in.gbuffer.height();
  // Seconds per pixel (printed with an SI prefix, e.g. 9.5n = 9.5 ns).
  state.counters["per_pixel"] =
      benchmark::Counter(pixels * double(state.iterations()), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void BM_Stream(benchmark::State& state) {
  const int m = int(state.range(0));
  const std::size_t bytes = up::Upsampler::streamed_bytes(options(m), kW, kH, kK, 3);
  const std::size_t n = bytes / 2;  // memcpy reads n bytes and writes n bytes
  std::unique_ptr<char[]> src(new char[n]), dst(new char[n]);
  std::memset(src.get(), 1, n);
  std::memset(dst.get(), 2, n);
  for (auto _ : state) {
    temporal::parallel_chunks(n, [&](std::size_t b, std::size_t e) { std::memcpy(dst.get() + b, src.get() + b, e - b); },
                              1 << 16);
    benchmark::ClobberMemory();
  }
  state.SetLabel(std::string("stream bound of ") + name(m));
  state.counters["MB"] = double(bytes) / 1e6;
}

}  // namespace

// UPSAMPLE_BENCH_ITERATIONS=N fixes the iteration count (for `perf stat -e cycles,instructions` comparisons on a
// busy machine: run with two counts and divide the difference of the counters by the difference of N).
int main(int argc, char** argv) {
  const char* fixed = std::getenv("UPSAMPLE_BENCH_ITERATIONS");
  const benchmark::IterationCount n = fixed ? std::atoll(fixed) : 0;
  const int last = int(up::method_variants().size()) - 1;
  auto* u = benchmark::RegisterBenchmark("BM_Upsample", BM_Upsample)->DenseRange(0, last)->Unit(benchmark::kMillisecond)->UseRealTime();
  auto* m = benchmark::RegisterBenchmark("BM_Stream", BM_Stream)->DenseRange(0, last)->Unit(benchmark::kMillisecond)->UseRealTime();
  // One thread's time per pixel of spatial, temporal, herzog, drobot and taau.
  const std::vector<int64_t> per_pixel = {variant_index("spatial"), variant_index("temporal"), variant_index("herzog"),
                                          variant_index("drobot"), variant_index("taau")};
  auto* p = benchmark::RegisterBenchmark("BM_PerPixel", BM_PerPixel)
                ->ArgsProduct({per_pixel, {1, 4}})
                ->Unit(benchmark::kMillisecond)
                ->UseRealTime();
  if (n > 0) {
    u->Iterations(n);
    m->Iterations(n);
    p->Iterations(n);
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
