// Benchmarks of issue 2, in one run:
//  * EXR read + write of a 1280x1024 G-buffer frame (14 channels, one part per layer, ZIP) through libtemporal,
//    next to `oiiotool -a IN -o OUT` doing the same copy (a process per copy, timed from here);
//  * `compare`'s time per 1080p frame (the tool as a process, one frame and ten frames; the library with I/O;
//    the metric kernels alone), next to `idiff` on the same pair.
// External tools that are not in PATH are skipped with a message. Numbers are reported in docs/compare.md.
#include "temporal/compare/comparison.h"
#include "temporal/io/exr.h"
#include "temporal/core/image.h"
#include "temporal/metrics/metrics.h"
#include "temporal/metrics/flicker.h"
#include "temporal/core/reproject.h"

#include <benchmark/benchmark.h>

#include <sys/resource.h>
#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>

namespace {

namespace fs = std::filesystem;
using namespace temporal;

fs::path scratch() {
  static const fs::path dir = [] {
    fs::path d = fs::path(TEMPORAL_BENCH_SCRATCH);
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

bool in_path(const std::string& program) {
  return std::system(("command -v " + program + " >/dev/null 2>&1").c_str()) == 0;
}

// Smooth fields plus a little noise: compresses like a rendered frame, not like white noise or a flat image.
Image gbuffer_frame(int w, int h, unsigned seed) {
  Image img(w, h);
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.0f, 0.01f);
  auto fill = [&](const char* name, auto f) {
    float* p = img.add_channel(name);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) p[std::size_t(y) * std::size_t(w) + std::size_t(x)] = f(float(x) / float(w), float(y) / float(h)) + noise(rng);
  };
  fill("R", [](float x, float y) { return 0.5f + 0.4f * std::sin(9.0f * x + 4.0f * y); });
  fill("G", [](float x, float y) { return 0.5f + 0.4f * std::sin(7.0f * x - 5.0f * y); });
  fill("B", [](float x, float y) { return 0.5f + 0.4f * std::cos(6.0f * x * y); });
  fill("A", [](float, float) { return 1.0f; });
  fill("depth.Z", [](float x, float y) { return 2.0f + 10.0f * x * y; });
  fill("N.X", [](float x, float) { return x - 0.5f; });
  fill("N.Y", [](float, float y) { return 0.8f - 0.2f * y; });
  fill("N.Z", [](float x, float y) { return 0.3f * x + 0.1f * y; });
  fill("motion.X", [](float x, float) { return -2.0f + x; });
  fill("motion.Y", [](float, float y) { return 0.5f * y; });
  fill("albedo.R", [](float x, float) { return 0.8f * x; });
  fill("albedo.G", [](float, float y) { return 0.6f * y; });
  fill("albedo.B", [](float, float) { return 0.5f; });
  std::uint32_t* id = img.add_uint_channel("id");
  for (std::size_t i = 0; i < img.pixel_count(); ++i) id[i] = std::uint32_t(1 + (i / 4096) % 7);
  return img;
}

const std::string& gbuffer_file() {
  static const std::string path = [] {
    const auto p = (scratch() / "gbuffer.0000.exr").string();
    if (!write_exr(p, gbuffer_frame(1280, 1024, 1))) std::abort();
    return p;
  }();
  return path;
}

// Ten 1080p colour frames: reference and a noisy test.
struct Frames1080 {
  std::string ref_pattern, test_pattern, ref0, test0;
};
const Frames1080& frames_1080() {
  static const Frames1080 f = [] {
    Frames1080 out;
    out.ref_pattern = (scratch() / "ref1080.####.exr").string();
    out.test_pattern = (scratch() / "test1080.####.exr").string();
    std::mt19937 rng(3);
    std::normal_distribution<float> noise(0.0f, 0.03f);
    for (int frame = 0; frame < 10; ++frame) {
      Image ref = gbuffer_frame(1920, 1080, unsigned(frame));
      for (const char* c : {"A", "depth.Z", "N.X", "N.Y", "N.Z", "motion.X", "motion.Y", "albedo.R", "albedo.G",
                            "albedo.B", "id"})
        ref.remove_channel(c);
      Image test = ref;
      for (const char* c : {"R", "G", "B"}) {
        float* p = test.plane(c);
        for (std::size_t i = 0; i < test.pixel_count(); ++i) p[i] = std::clamp(p[i] + noise(rng), 0.0f, 1.0f);
        float* q = ref.plane(c);
        for (std::size_t i = 0; i < ref.pixel_count(); ++i) q[i] = std::clamp(q[i], 0.0f, 1.0f);
      }
      char digits[8];
      std::snprintf(digits, sizeof digits, "%04d", frame);
      const auto rp = (scratch() / (std::string("ref1080.") + digits + ".exr")).string();
      const auto tp = (scratch() / (std::string("test1080.") + digits + ".exr")).string();
      if (!write_exr(rp, ref) || !write_exr(tp, test)) std::abort();
      if (frame == 0) {
        out.ref0 = rp;
        out.test0 = tp;
      }
    }
    return out;
  }();
  return f;
}

// Runs a shell command per iteration and reports its wall time (process start included). Exit codes up to
// `max_ok` count as success (idiff exits 2 when the images differ, which they do here).
// Also reports the child's CPU time (user + system, all its threads) per iteration as `child_cpu_ms`: on a
// loaded machine wall time mostly measures the load, CPU time the work.
double children_cpu_ms() {
  rusage u{};
  getrusage(RUSAGE_CHILDREN, &u);
  return (double(u.ru_utime.tv_sec) + double(u.ru_stime.tv_sec)) * 1e3 +
         (double(u.ru_utime.tv_usec) + double(u.ru_stime.tv_usec)) * 1e-3;
}

double time_command(benchmark::State& state, const std::string& command, int max_ok = 0) {
  const double cpu0 = children_cpu_ms();
  double total = 0.0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    const int rc = std::system(command.c_str());
    const auto t1 = std::chrono::steady_clock::now();
    if (rc == -1 || !WIFEXITED(rc) || WEXITSTATUS(rc) > max_ok) {
      state.SkipWithError(("command failed: " + command).c_str());
      return total;
    }
    state.SetIterationTime(std::chrono::duration<double>(t1 - t0).count());
    total += std::chrono::duration<double>(t1 - t0).count();
  }
  if (state.iterations() > 0) state.counters["child_cpu_ms"] = (children_cpu_ms() - cpu0) / double(state.iterations());
  return total;
}

// --- EXR read + write, 1280x1024 G-buffer -----------------------------------------------------------------

void BM_ExrRead_GBuffer1280x1024(benchmark::State& state) {
  const auto& in = gbuffer_file();
  for (auto _ : state) {
    auto img = read_exr(in);
    if (!img) state.SkipWithError(img.error().message.c_str());
    benchmark::DoNotOptimize(img);
  }
}
BENCHMARK(BM_ExrRead_GBuffer1280x1024)->MeasureProcessCPUTime()->UseRealTime()->Unit(benchmark::kMillisecond);

void BM_ExrReadMotionOnly_GBuffer1280x1024(benchmark::State& state) {
  const auto& in = gbuffer_file();
  for (auto _ : state) {
    auto img = read_exr(in, ExrSelection{{"motion"}});
    if (!img) state.SkipWithError(img.error().message.c_str());
    benchmark::DoNotOptimize(img);
  }
}
BENCHMARK(BM_ExrReadMotionOnly_GBuffer1280x1024)->MeasureProcessCPUTime()->UseRealTime()->Unit(benchmark::kMillisecond);

void BM_ExrReadWrite_GBuffer1280x1024(benchmark::State& state) {
  const auto& in = gbuffer_file();
  const auto out = (scratch() / "copy-temporal.exr").string();
  for (auto _ : state) {
    auto img = read_exr(in);
    if (!img || !write_exr(out, *img)) {
      state.SkipWithError("read or write failed");
      break;
    }
  }
}
BENCHMARK(BM_ExrReadWrite_GBuffer1280x1024)->MeasureProcessCPUTime()->UseRealTime()->Unit(benchmark::kMillisecond);

void BM_OiiotoolCopy_GBuffer1280x1024(benchmark::State& state) {
  if (!in_path("oiiotool")) {
    state.SkipWithError("oiiotool is not in PATH (Debian: openimageio-tools)");
    return;
  }
  const auto out = (scratch() / "copy-oiiotool.exr").string();
  time_command(state, "oiiotool -a " + gbuffer_file() + " -o " + out + " >/dev/null 2>&1");
}
BENCHMARK(BM_OiiotoolCopy_GBuffer1280x1024)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(5);

// --- compare per 1080p frame --------------------------------------------------------------------------------

void BM_CompareTool_1080p_1Frame(benchmark::State& state) {
  const auto& f = frames_1080();
  time_command(state, std::string(TEMPORAL_COMPARE_PATH) + " --reference " + f.ref_pattern + " " + f.test_pattern +
                          " --frames 0-0 >/dev/null 2>&1");
}
BENCHMARK(BM_CompareTool_1080p_1Frame)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(5);

void BM_CompareTool_1080p_10Frames(benchmark::State& state) {
  const auto& f = frames_1080();
  const double total = time_command(state, std::string(TEMPORAL_COMPARE_PATH) + " --reference " + f.ref_pattern +
                                              " " + f.test_pattern + " --frames 0-9 >/dev/null 2>&1");
  if (state.iterations() == 0) return;
  state.counters["wall_ms_per_frame"] = total * 1e3 / (double(state.iterations()) * 10.0);
  state.counters["cpu_ms_per_frame"] = state.counters["child_cpu_ms"] / 10.0;
}
BENCHMARK(BM_CompareTool_1080p_10Frames)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_Idiff_1080p(benchmark::State& state) {
  if (!in_path("idiff")) {
    state.SkipWithError("idiff is not in PATH (Debian: openimageio-tools)");
    return;
  }
  const auto& f = frames_1080();
  time_command(state, "idiff " + f.ref0 + " " + f.test0 + " >/dev/null 2>&1", 2);
}
BENCHMARK(BM_Idiff_1080p)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(5);

// The library on ten frames (reads included), per frame.
void BM_CompareLibrary_1080p(benchmark::State& state) {
  const auto& f = frames_1080();
  ComparisonSetup setup;
  setup.reference = f.ref_pattern;
  setup.tests = {f.test_pattern};
  double metrics_ms = 0.0;
  for (auto _ : state) {
    auto report = compare_sequences(setup);
    if (!report) {
      state.SkipWithError(report.error().message.c_str());
      break;
    }
    for (const auto& m : report->sequences[0].frames) metrics_ms += m.metrics_ms;
  }
  state.SetItemsProcessed(state.iterations() * 10);
  state.counters["metrics_ms_per_frame"] = metrics_ms / (double(state.iterations()) * 10.0);
}
BENCHMARK(BM_CompareLibrary_1080p)->MeasureProcessCPUTime()->UseRealTime()->Unit(benchmark::kMillisecond)->Iterations(2);

// Kernels alone on one 1080p frame in memory: luminance, PSNR, SSIM, warp + flicker.
void BM_CompareKernels_1080p(benchmark::State& state) {
  const auto& f = frames_1080();
  auto ref = read_exr(f.ref0, {{"rgb"}});
  auto test = read_exr(f.test0, {{"rgb"}});
  if (!ref || !test) {
    state.SkipWithError("cannot read the 1080p frames");
    return;
  }
  const int w = ref->width(), h = ref->height();
  const std::size_t n = ref->pixel_count();
  std::vector<const float*> rp = {ref->plane("R"), ref->plane("G"), ref->plane("B")};
  std::vector<const float*> tp = {test->plane("R"), test->plane("G"), test->plane("B")};
  std::vector<float> ry(n), ty(n), warped(n), rd(n), td(n), mx(n, -1.5f), my(n, 0.25f);
  std::vector<std::uint8_t> valid(n);
  for (auto _ : state) {
    finite_mask(tp, rp, n, valid.data());
    auto e = squared_error(tp, rp, w, h, valid.data(), nullptr);
    luminance_plane(rp, n, ry.data());
    luminance_plane(tp, n, ty.data());
    auto s = ssim(ty.data(), ry.data(), w, h, valid.data(), nullptr, SsimOptions{});
    reproject::Frames fr;
    fr.width = w;
    fr.height = h;
    fr.motion_x = mx.data();
    fr.motion_y = my.data();
    const float* prev[] = {ry.data(), ty.data()};
    float* warped2[] = {warped.data(), rd.data()};
    reproject::warp_planes(fr, prev, warped2);  // both previous planes share one motion field, as in compare
    temporal_delta(ty.data(), rd.data(), n, td.data());
    temporal_delta(ry.data(), warped.data(), n, rd.data());
    auto fl = flicker(td.data(), rd.data(), w, h, valid.data(), nullptr);
    benchmark::DoNotOptimize(e);
    benchmark::DoNotOptimize(s);
    benchmark::DoNotOptimize(fl);
  }
}
BENCHMARK(BM_CompareKernels_1080p)->MeasureProcessCPUTime()->UseRealTime()->Unit(benchmark::kMillisecond);

void BM_Ssim_1080p(benchmark::State& state) {
  const int w = 1920, h = 1080;
  std::vector<float> a(std::size_t(w) * h), b(a.size());
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (std::size_t i = 0; i < a.size(); ++i) {
    a[i] = u(rng);
    b[i] = 0.9f * a[i] + 0.1f * u(rng);
  }
  for (auto _ : state) {
    auto s = ssim(a.data(), b.data(), w, h, nullptr, nullptr, SsimOptions{});
    benchmark::DoNotOptimize(s);
  }
}
BENCHMARK(BM_Ssim_1080p)->MeasureProcessCPUTime()->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
