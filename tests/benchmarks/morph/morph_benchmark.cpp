// Seed 004 Table 1 on the CPU: the two in-between frames of a 40 -> 120 Hz upsampling at 1024x1024, split into
// motion flow (snapped grid), morph (warped grid rasterisation) and blur (pyramid, reconstruction,
// compensation). Counters flow_ms, morph_ms, blur_ms are per rendered frame (= per two in-between frames).
// One benchmark per method of the registry (temporal/morph/methods.h): BM_<method>1024x3/<threads>.
#include "temporal/morph/hold_blur.h"
#include "temporal/morph/methods.h"
#include "temporal/morph/morph.h"
#include "temporal/core/parallel.h"

#include "synthetic.h"

#include <benchmark/benchmark.h>

namespace {

using namespace temporal;
using namespace temporal::morph;

// A panning camera over a textured plane with eight occluders moving in different directions.
struct Scene {
  int w = 1024, h = 1024;
  Image color, gbuffer;
  Scene() {
    auto occluder = [](float x, float y, int& index) {
      for (int i = 0; i < 8; ++i) {
        const float cx = 128.0f + 110.0f * float(i), cy = 160.0f + 95.0f * float(i);
        if (std::abs(x - cx) < 60.0f && std::abs(y - cy) < 45.0f) {
          index = i;
          return true;
        }
      }
      return false;
    };
    color = test::make_color(w, h, [&](float x, float y, int c) {
      int i = 0;
      return occluder(x, y, i) ? 0.8f - 0.3f * test::texture(y, x, c) : test::texture(x, y, c);
    });
    gbuffer = test::make_gbuffer(w, h, [&](int x, int y, float& mx, float& my, float& d) {
      int i = 0;
      if (occluder(float(x) + 0.5f, float(y) + 0.5f, i)) {
        mx = -6.0f + float(i);
        my = 2.0f - 0.5f * float(i);
        d = 2.0f + 0.1f * float(i);
      } else {
        mx = -3.0f;
        my = -1.0f;
        d = 20.0f;
      }
    });
  }
};

const Scene& scene() {
  static const Scene s;
  return s;
}

void run_method(benchmark::State& state, const std::string& method) {
  const Scene& s = scene();
  // Argument: worker threads (0: every core). One thread gives the total work, robust to a loaded machine.
  const ThreadLimit limit(int(state.range(0)));
  MorphOptions o;
  o.method = method;
  o.factor = 3;
  Morpher m(o);
  std::vector<Image> out;
  MorphTimings sum;
  for (auto _ : state) {
    MorphTimings t;
    if (!m.process(s.color, &s.gbuffer, &s.color, out, &t)) state.SkipWithError("process failed");
    sum.flow_ms += t.flow_ms;
    sum.morph_ms += t.morph_ms;
    sum.blur_ms += t.blur_ms;
    benchmark::DoNotOptimize(out[1].plane("R"));
  }
  const double n = double(state.iterations());
  state.counters["flow_ms"] = sum.flow_ms / n;
  state.counters["morph_ms"] = sum.morph_ms / n;
  state.counters["blur_ms"] = sum.blur_ms / n;
  state.counters["total_ms"] = sum.total_ms() / n;
}

// The perceived-image simulation of one displayed frame (window 3) at 1024x1024.
void BM_PerceiveHold1024(benchmark::State& state) {
  const Scene& s = scene();
  const Image* frames[3] = {&s.color, &s.color, &s.color};
  for (auto _ : state) {
    auto p = perceive_hold(frames, {"R", "G", "B"}, s.gbuffer.plane("motion.X"), s.gbuffer.plane("motion.Y"));
    benchmark::DoNotOptimize(p);
  }
}

[[maybe_unused]] const bool registered = [] {
  for (const MethodEntry* e : registry())
    benchmark::RegisterBenchmark(("BM_" + e->info.name + "1024x3").c_str(), run_method, e->info.name)
        ->Arg(0)
        ->Arg(1)
        ->Unit(benchmark::kMillisecond)
        ->MeasureProcessCPUTime()
        ->UseRealTime();
  return true;
}();
BENCHMARK(BM_PerceiveHold1024)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
