// ms per frame of each upsampling method and named variant of the method table (temporal/upsample/methods.h) at
// 1280x1024 (factor 4, R,G,B payload) and, in the same run, the
// time to stream the bytes the method must read and write (Upsampler::streamed_bytes: G-buffer planes,
// payload in and out, full-resolution histories read and written once), measured as a parallel copy
// moving that many bytes (half read, half written) from DRAM to DRAM with non-temporal stores (BM_Stream;
// BM_StreamL3: the same copy of one buffer pair, part of it from L3). Targets (issue 4): herzog <= 1.5x
// spatial, and within 2.5x of its streaming bound.
// BM_Interleaved: issue 27's ratios (herzog and taau against spatial, drobot against its bound) from frames of the
// two methods and copies of the bound interleaved in one sequence. BM_Dispatch: what the run-time dispatch of the
// kernel copies buys each method (the x86-64-v2 copies against the active level's, interleaved the same way).
#include "synthetic.h"
#include "upsample_variants.h"

#include "temporal/core/isa.h"
#include "temporal/core/parallel.h"
#include "temporal/upsample/methods.h"
#include "temporal/upsample/upsample.h"

#include <benchmark/benchmark.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <vector>

#include <unistd.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

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

// UPSAMPLE_BENCH_ARENA=N runs BM_Upsample inside a task arena of N threads: herzog and drobot size their chunks of
// rows for N threads (temporal::rows_per_chunk), while only the machine's cores run them. On a 2-core machine N = 16
// shows what the smaller chunks of a 16-core machine cost in work (their extra edge rows), not their parallel speed.
int bench_arena() {
  const char* n = std::getenv("UPSAMPLE_BENCH_ARENA");
  return n ? std::max(0, std::atoi(n)) : 0;
}

void BM_Upsample(benchmark::State& state) {
  const int m = int(state.range(0));
  const Inputs& in = inputs();
  auto body = [&] {
    up::Upsampler u(options(m));
    std::size_t t = 0;
    for (int i = 0; i < 2 * kK * kK; ++i)  // warm the histories and buffers
      (void)u.process(in.gbuffer, in.low[t++ % in.low.size()], kRGB, false);
    for (auto _ : state) {
      auto r = u.process(in.gbuffer, in.low[t++ % in.low.size()], kRGB, false);
      benchmark::DoNotOptimize(r);
    }
  };
  if (const int n = bench_arena(); n > 0)
    tbb::task_arena(n).execute(body);
  else
    body();
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

// The bound: the fastest copy of the method's bytes from DRAM to DRAM, half of them read, half written.
// - Non-temporal stores (SSE2, every x86-64): a memcpy in 64 KiB chunks (the bound until 2026-11-26) is below
//   glibc's non-temporal threshold and stores through the cache, so every destination line is first read (a
//   third stream the method's byte count does not contain) and the writes evict the source from L3.
// - Sources from DRAM (BM_Stream): the copy rotates over enough buffer pairs that the sources read between two
//   uses of one pair exceed twice the L3 (64 MB on the build machine's 32 MB L3: 5 pairs for drobot). One pair
//   copied again and again (BM_StreamL3, the old bound's way) reads part of its source from L3, a share that
//   depends on what else runs on the host: drobot's old bound (42.6 MB) moved between 0.7 and 1.95 ms in runs
//   of the same binary, BM_StreamL3 between 0.44 and 0.81 ms (docs/history/upsample-st-speed.md, "Issue 27, third
//   pass").
// - Every buffer is written before the timed loop (no page faults inside it); the chunks are 64 KiB of whole
//   cache lines, shared dynamically by the threads (a thread held up by another process does not leave half
//   the copy waiting).
void stream_copy(char* dst, const char* src, std::size_t n) {
#if defined(__SSE2__)
  for (std::size_t i = 0; i < n; i += 64) {
    const __m128i a = _mm_load_si128(reinterpret_cast<const __m128i*>(src + i));
    const __m128i b = _mm_load_si128(reinterpret_cast<const __m128i*>(src + i + 16));
    const __m128i c = _mm_load_si128(reinterpret_cast<const __m128i*>(src + i + 32));
    const __m128i d = _mm_load_si128(reinterpret_cast<const __m128i*>(src + i + 48));
    _mm_stream_si128(reinterpret_cast<__m128i*>(dst + i), a);
    _mm_stream_si128(reinterpret_cast<__m128i*>(dst + i + 16), b);
    _mm_stream_si128(reinterpret_cast<__m128i*>(dst + i + 32), c);
    _mm_stream_si128(reinterpret_cast<__m128i*>(dst + i + 48), d);
  }
#else
  std::memcpy(dst, src, n);
#endif
}

// The L3 size: Linux's cache description (what lscpu shows), else glibc's, else the build machine's 32 MB. glibc's
// sysconf(_SC_LEVEL3_CACHE_SIZE) says 320 MB on the build machine's VM (lscpu and sysfs: 32 MB), which would
// allocate ten times the buffers needed.
std::size_t l3_bytes() {
  if (std::FILE* f = std::fopen("/sys/devices/system/cpu/cpu0/cache/index3/size", "r")) {
    unsigned long v = 0;
    char unit = 0;
    const int got = std::fscanf(f, "%lu%c", &v, &unit);
    std::fclose(f);
    const std::size_t scale = got == 2 && unit == 'K' ? 1024 : got == 2 && unit == 'M' ? std::size_t(1) << 20 : 1;
    if (got >= 1 && v > 0) return std::size_t(v) * scale;
  }
#if defined(_SC_LEVEL3_CACHE_SIZE)
  if (const long s = sysconf(_SC_LEVEL3_CACHE_SIZE); s > 0) return std::size_t(s);
#endif
  return std::size_t(32) << 20;
}

struct PlaneFree {
  void operator()(char* p) const { temporal::free_plane_memory(p); }
};

// The copy of one method's bytes (see above): `pairs` buffer pairs, one copied per call of run().
class StreamCopy {
 public:
  StreamCopy(int m, bool from_dram) {
    const std::size_t bytes = up::Upsampler::streamed_bytes(options(m), kW, kH, kK, 3);
    lines_ = (bytes / 2 + kLine - 1) / kLine;  // memcpy reads n bytes and writes n bytes
    const std::size_t n = lines_ * kLine;
    const std::size_t pairs = from_dram ? 1 + (2 * l3_bytes() + n - 1) / n : 1;
    for (std::size_t p = 0; p < pairs; ++p) {
      // The planes' memory (temporal::allocate_plane_memory: huge pages where the system gives them), as the
      // methods' planes get: the bound is timed on the same pages.
      src_.emplace_back(static_cast<char*>(temporal::allocate_plane_memory(n)));  // throws when out of memory
      dst_.emplace_back(static_cast<char*>(temporal::allocate_plane_memory(n)));
      std::memset(src_.back().get(), 1, n);
      std::memset(dst_.back().get(), 2, n);
    }
  }
  bool ok() const { return !src_.empty(); }
  void run() {
    const char* s = src_[p_].get();
    char* d = dst_[p_].get();
    p_ = (p_ + 1) % src_.size();
    temporal::parallel_chunks(
        lines_, [&](std::size_t b, std::size_t e) { stream_copy(d + b * kLine, s + b * kLine, (e - b) * kLine); },
        kChunkLines);
#if defined(__SSE2__)
    _mm_sfence();  // the streamed stores are globally visible before the clock stops
#endif
    benchmark::ClobberMemory();
  }

 private:
  static constexpr std::size_t kLine = 64, kChunkLines = 1024;  // 64 KiB chunks
  std::size_t lines_ = 0, p_ = 0;
  std::vector<std::unique_ptr<char, PlaneFree>> src_, dst_;
};

void stream(benchmark::State& state, bool from_dram) {
  const int m = int(state.range(0));
  StreamCopy copy(m, from_dram);
  if (!copy.ok()) {
    state.SkipWithError("out of memory for the stream buffers");
    return;
  }
  for (auto _ : state) copy.run();
  state.SetLabel(std::string(from_dram ? "stream bound of " : "L3-assisted copy for ") + name(m));
  state.counters["MB"] = double(up::Upsampler::streamed_bytes(options(m), kW, kH, kK, 3)) / 1e6;
}

// Issue 27's two ratios from one interleaved sequence: per iteration one frame of spatial, one copy of method m's
// bytes (BM_Stream's), one frame of m and another copy, each timed on its own; the counters are the ratios of the
// summed times, x_spatial = m / spatial and x_bound = m / its streaming bound (the mean of the two copies). On a
// host whose speed drifts between runs (the build VM: 20 % and more within minutes, docs/upsample-st.md) separate
// runs of BM_Upsample and BM_Stream see different machines; here the three share every stretch of time,
// milliseconds apart. Every frame starts after a copy, which replaces most of the L3 (it reads half the method's
// bytes from DRAM): neither method finds data the other just read, and both start from the same state. The
// reported time is m's.
void BM_Interleaved(benchmark::State& state) {
  const int m = int(state.range(0));
  const Inputs& in = inputs();
  up::Upsampler base(options(variant_index("spatial"))), method(options(m));
  StreamCopy copy(m, true);
  if (!copy.ok()) {
    state.SkipWithError("out of memory for the stream buffers");
    return;
  }
  std::size_t t = 0;
  for (int i = 0; i < 2 * kK * kK; ++i, ++t) {  // warm the histories and buffers
    (void)base.process(in.gbuffer, in.low[t % in.low.size()], kRGB, false);
    (void)method.process(in.gbuffer, in.low[t % in.low.size()], kRGB, false);
  }
  copy.run();
  using Clock = std::chrono::steady_clock;
  auto seconds = [](Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); };
  double t_base = 0.0, t_method = 0.0, t_copy = 0.0;
  for (auto _ : state) {
    const Image& low = in.low[t++ % in.low.size()];
    const auto c0 = Clock::now();
    auto rb = base.process(in.gbuffer, low, kRGB, false);
    const auto c1 = Clock::now();
    copy.run();
    const auto c2 = Clock::now();
    auto rm = method.process(in.gbuffer, low, kRGB, false);
    const auto c3 = Clock::now();
    copy.run();
    const auto c4 = Clock::now();
    benchmark::DoNotOptimize(rb);
    benchmark::DoNotOptimize(rm);
    t_base += seconds(c0, c1);
    t_method += seconds(c2, c3);
    t_copy += 0.5 * (seconds(c1, c2) + seconds(c3, c4));
    state.SetIterationTime(seconds(c2, c3));
  }
  state.SetLabel(std::string(name(m)) + " interleaved with spatial and its stream bound");
  state.counters["x_spatial"] = t_base > 0.0 ? t_method / t_base : 0.0;
  state.counters["x_bound"] = t_copy > 0.0 ? t_method / t_copy : 0.0;
  const double it = double(std::max<benchmark::IterationCount>(1, state.iterations()));
  state.counters["spatial_ms"] = t_base / it * 1e3;
  state.counters["bound_ms"] = t_copy / it * 1e3;
}

// What the run-time dispatch buys each method (issue 27): frames of method m run by the x86-64-v2 kernel copies (the
// portable baseline, what every x86-64 CPU runs) and by the copies of the active level (v3: AVX2 and FMA; v4:
// AVX-512), interleaved in one sequence as in BM_Interleaved: per iteration one frame at each level, in alternating
// order, each after a copy of the method's bytes (which replaces most of the L3). Each level has its own Upsampler
// (its own history), and every call of a v2 frame runs under isa::ScopedLevel, so the state and the kernels that
// dispatch per call (the reprojection module's) all run their v2 copies (frame.cpp's code has one copy only). x_v2 =
// v2 time / active time, both summed over the iterations. A ratio near 1 says the method spends its time in code
// compiled for the baseline only (temporal's frame code until 2026-11-29, found then by
// tests/benchmarks/portable_vs_native.sh). The reported time is the active level's. Skipped in a build without
// dispatch (TEMPORAL_NATIVE) or on a CPU without v3.
void BM_Dispatch(benchmark::State& state) {
  namespace isa = temporal::isa;
  if (!isa::dispatching() || !isa::supported(isa::Level::V3) || isa::active() == isa::Level::V2) {
    state.SkipWithError("no kernel copies above x86-64-v2 to compare with (TEMPORAL_NATIVE build, CPU without AVX2, "
                        "or TEMPORAL_ISA=v2)");
    return;
  }
  const int m = int(state.range(0));
  const Inputs& in = inputs();
  up::Upsampler base(options(m)), top(options(m));
  StreamCopy copy(m, true);
  if (!copy.ok()) {
    state.SkipWithError("out of memory for the stream buffers");
    return;
  }
  auto run = [&](bool v2, const Image& low) {
    if (!v2) return top.process(in.gbuffer, low, kRGB, false);
    isa::ScopedLevel level(isa::Level::V2);
    return base.process(in.gbuffer, low, kRGB, false);
  };
  std::size_t t = 0;
  for (int i = 0; i < 2 * kK * kK; ++i, ++t) {  // warm the histories and buffers
    (void)run(true, in.low[t % in.low.size()]);
    (void)run(false, in.low[t % in.low.size()]);
  }
  using Clock = std::chrono::steady_clock;
  auto seconds = [](Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); };
  double t_v2 = 0.0, t_top = 0.0;
  bool v2_first = false;
  for (auto _ : state) {
    const Image& low = in.low[t++ % in.low.size()];
    v2_first = !v2_first;
    double frame_top = 0.0;
    for (int r = 0; r < 2; ++r) {
      const bool v2 = (r == 0) == v2_first;
      copy.run();
      const auto c0 = Clock::now();
      auto out = run(v2, low);
      const auto c1 = Clock::now();
      benchmark::DoNotOptimize(out);
      (v2 ? t_v2 : frame_top) += seconds(c0, c1);
    }
    t_top += frame_top;
    state.SetIterationTime(frame_top);
  }
  state.SetLabel(std::string(name(m)) + ": v2 copies against " + std::string(isa::name(isa::active())));
  const double it = double(std::max<benchmark::IterationCount>(1, state.iterations()));
  state.counters["v2_ms"] = t_v2 / it * 1e3;
  state.counters["active_ms"] = t_top / it * 1e3;
  state.counters["x_v2"] = t_top > 0.0 ? t_v2 / t_top : 0.0;
}

void BM_Stream(benchmark::State& state) { stream(state, true); }
void BM_StreamL3(benchmark::State& state) { stream(state, false); }

}  // namespace

// UPSAMPLE_BENCH_ITERATIONS=N fixes the iteration count (for `perf stat -e cycles,instructions` comparisons on a
// busy machine: run with two counts and divide the difference of the counters by the difference of N).
int main(int argc, char** argv) {
  const char* fixed = std::getenv("UPSAMPLE_BENCH_ITERATIONS");
  const benchmark::IterationCount n = fixed ? std::atoll(fixed) : 0;
  const int last = int(up::method_variants().size()) - 1;
  auto* u = benchmark::RegisterBenchmark("BM_Upsample", BM_Upsample)->DenseRange(0, last)->Unit(benchmark::kMillisecond)->UseRealTime();
  auto* m = benchmark::RegisterBenchmark("BM_Stream", BM_Stream)->DenseRange(0, last)->Unit(benchmark::kMillisecond)->UseRealTime();
  auto* d = benchmark::RegisterBenchmark("BM_StreamL3", BM_StreamL3)
                ->DenseRange(0, last)
                ->Unit(benchmark::kMillisecond)
                ->UseRealTime();
  // Issue 27's ratios from interleaved frames: herzog, drobot and taau.
  auto* v = benchmark::RegisterBenchmark("BM_Interleaved", BM_Interleaved)
                ->Arg(variant_index("herzog"))
                ->Arg(variant_index("drobot"))
                ->Arg(variant_index("taau"))
                ->Unit(benchmark::kMillisecond)
                ->UseManualTime();
  // The v2 copies against the active level's, every method and variant.
  auto* g = benchmark::RegisterBenchmark("BM_Dispatch", BM_Dispatch)
                ->DenseRange(0, last)
                ->Unit(benchmark::kMillisecond)
                ->UseManualTime();
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
    d->Iterations(n);
    p->Iterations(n);
    v->Iterations(n);
    g->Iterations(n);
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
