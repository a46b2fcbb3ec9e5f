// FLIP's cost against compare's PSNR + SSIM, on the same 1920x1080 pair in one run (issue 13: FLIP in at most
// twice the time of PSNR + SSIM). Each benchmark does what `compare` does per test frame:
//   PsnrSsim: validity of both images, PSNR over R,G,B, luminance of both, PSNR of luminance, SSIM;
//   FlipLdr:  compare --flip ldr (LDR-FLIP of the clamped linear values) and its pooling (mean, weighted
//             quartiles);
//   FlipHdr:  compare --flip hdr (HDR-FLIP, ACES, automatic exposures) and its pooling; the label gives the
//             number of exposures, which HDR-FLIP's cost is proportional to.
// The pair is synthetic but shaped like a rendered frame: smooth shading, textured regions, hard edges and a
// few highlights (luminance up to ~10: 5 exposures); the test adds noise, smears a region and shifts an edge.
// The argument is the thread count (0: every core; 1: one thread, the per-pixel cost without the scheduling).
// Numbers are reported in docs/compare.md ("FLIP").
#include "temporal/core/parallel.h"
#include "temporal/metrics/flip.h"
#include "temporal/metrics/metrics.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

namespace {

using namespace temporal;

constexpr int kW = 1920, kH = 1080;

struct Pair {
  std::vector<float> ref[3], test[3];
};

const Pair& pair_1080p() {
  static const Pair pair = [] {
    Pair p;
    const std::size_t n = std::size_t(kW) * std::size_t(kH);
    for (int c = 0; c < 3; ++c) {
      p.ref[c].resize(n);
      p.test[c].resize(n);
    }
    std::mt19937 rng(11);
    std::normal_distribution<float> noise(0.0f, 0.03f);
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) {
        const float u = float(x) / kW, v = float(y) / kH;
        // Sky gradient, a textured ground plane below a horizon, two discs with a hard rim, highlights.
        float rgb[3] = {0.25f + 0.3f * v, 0.35f + 0.25f * v, 0.6f - 0.2f * v};
        if (v > 0.55f) {
          const float t = 0.5f + 0.5f * std::sin(60.0f * u / (v - 0.45f)) * std::sin(25.0f / (v - 0.45f));
          rgb[0] = 0.15f + 0.35f * t;
          rgb[1] = 0.12f + 0.25f * t;
          rgb[2] = 0.08f + 0.1f * t;
        }
        const float d1 = std::hypot(u - 0.3f, v - 0.45f), d2 = std::hypot(u - 0.7f, v - 0.5f);
        if (d1 < 0.15f) {
          const float shade = 0.2f + 0.8f * std::max(0.0f, 1.0f - d1 / 0.15f);
          rgb[0] = 0.8f * shade;
          rgb[1] = 0.2f * shade;
          rgb[2] = 0.1f * shade;
        }
        if (d2 < 0.12f) {
          const float shade = 0.3f + 0.7f * (0.5f + 0.5f * std::sin(80.0f * u));
          for (float& c : rgb) c = 0.6f * shade;
        }
        const float hl = std::exp(-(std::pow(u - 0.33f, 2.0f) + std::pow(v - 0.4f, 2.0f)) / 0.0004f);
        for (float& c : rgb) c += 10.0f * hl;
        const std::size_t i = std::size_t(y) * kW + std::size_t(x);
        for (int c = 0; c < 3; ++c) {
          p.ref[c][i] = rgb[c];
          float t = rgb[c] * (1.0f + noise(rng));
          if (u > 0.6f && v > 0.7f) t = 0.25f + 0.5f * rgb[c];          // a smeared region
          if (std::fabs(u - 0.3f) < 0.002f && d1 < 0.16f) t = rgb[c] * 0.5f;  // a displaced edge
          p.test[c][i] = std::max(t, 0.0f);
        }
      }
    return p;
  }();
  return pair;
}

void BM_PsnrSsim_1080p(benchmark::State& state) {
  const ThreadLimit threads(int(state.range(0)));
  const Pair& p = pair_1080p();
  const std::size_t n = std::size_t(kW) * std::size_t(kH);
  const std::vector<const float*> rp = {p.ref[0].data(), p.ref[1].data(), p.ref[2].data()};
  const std::vector<const float*> tp = {p.test[0].data(), p.test[1].data(), p.test[2].data()};
  std::vector<float> ry(n), ty(n);
  std::vector<std::uint8_t> ref_valid(n), valid(n);
  for (auto _ : state) {
    finite_mask(rp, {}, n, ref_valid.data());
    finite_mask(tp, {}, n, valid.data());
    for (std::size_t i = 0; i < n; ++i) valid[i] &= ref_valid[i];
    const auto e = squared_error(tp, rp, kW, kH, valid.data(), nullptr);
    luminance_plane(rp, n, ry.data());
    luminance_plane(tp, n, ty.data());
    const float* typ = ty.data();
    const float* ryp = ry.data();
    const auto ey = squared_error({&typ, 1}, {&ryp, 1}, kW, kH, valid.data(), nullptr);
    auto s = ssim(ty.data(), ry.data(), kW, kH, valid.data(), nullptr, SsimOptions{});
    benchmark::DoNotOptimize(psnr_db(e.all, 1.0));
    benchmark::DoNotOptimize(psnr_db(ey.all, 1.0));
    benchmark::DoNotOptimize(s);
  }
}
BENCHMARK(BM_PsnrSsim_1080p)->Arg(0)->Arg(1)->MeasureProcessCPUTime()->UseRealTime()->Unit(benchmark::kMillisecond);

void flip_1080p(benchmark::State& state, FlipRange range) {
  const ThreadLimit threads(int(state.range(0)));
  const Pair& p = pair_1080p();
  const std::size_t n = std::size_t(kW) * std::size_t(kH);
  FlipOptions o;
  o.ldr_input = FlipLdrInput::Linear;
  FlipEvaluator evaluator(o);
  std::vector<float> map(n);
  const FlipImage ref{p.ref[0].data(), p.ref[1].data(), p.ref[2].data()};
  const FlipImage test{p.test[0].data(), p.test[1].data(), p.test[2].data()};
  int exposures = 0;
  double mean = 0.0;
  // One call outside the timing: the evaluator allocates its planes once, and compare keeps it for every frame.
  if (!evaluator.ldr(test, ref, kW, kH, nullptr, map.data())) state.SkipWithError("FLIP failed");
  for (auto _ : state) {
    if (range == FlipRange::Ldr) {
      if (!evaluator.ldr(test, ref, kW, kH, nullptr, map.data())) state.SkipWithError("FLIP failed");
    } else {
      auto e = evaluator.hdr(test, ref, kW, kH, nullptr, map.data());
      if (!e) state.SkipWithError("FLIP failed");
      else exposures = e->count;
    }
    const FlipStats s = flip_statistics(map);
    mean = s.mean;
    benchmark::DoNotOptimize(s);
  }
  state.SetLabel(range == FlipRange::Ldr ? "mean " + std::to_string(mean)
                                         : std::to_string(exposures) + " exposures, mean " + std::to_string(mean));
}
void BM_FlipLdr_1080p(benchmark::State& state) { flip_1080p(state, FlipRange::Ldr); }
void BM_FlipHdr_1080p(benchmark::State& state) { flip_1080p(state, FlipRange::Hdr); }
BENCHMARK(BM_FlipLdr_1080p)->Arg(0)->Arg(1)->MeasureProcessCPUTime()->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FlipHdr_1080p)->Arg(0)->Arg(1)->MeasureProcessCPUTime()->UseRealTime()->Unit(benchmark::kMillisecond);

// The pooling alone (sorting only the buckets that hold the weighted quartiles).
void BM_FlipStatistics_1080p(benchmark::State& state) {
  const Pair& p = pair_1080p();
  const std::size_t n = std::size_t(kW) * std::size_t(kH);
  std::vector<float> map(n);
  FlipOptions o;
  o.ldr_input = FlipLdrInput::Linear;
  FlipEvaluator(o).ldr({p.test[0].data(), p.test[1].data(), p.test[2].data()},
                       {p.ref[0].data(), p.ref[1].data(), p.ref[2].data()}, kW, kH, nullptr, map.data());
  for (auto _ : state) benchmark::DoNotOptimize(flip_statistics(map));
}
BENCHMARK(BM_FlipStatistics_1080p)->MeasureProcessCPUTime()->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
