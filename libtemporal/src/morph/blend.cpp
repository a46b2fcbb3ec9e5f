// `blend`: slot k = (1 - k/N) frame n + (k/N) frame n+1 in linear light. It needs frame n+1 before slot 1 of n
// can be shown: one rendered frame of added latency. The last frame, without a successor, is repeated.
#include "method_common.h"
#include "temporal/core/parallel.h"
#include "temporal/morph/gpu_methods.h"
#include "temporal/morph/methods.h"

#include <algorithm>

namespace temporal::morph {
namespace {

using namespace detail;

class Blend final : public MorphMethod {
 public:
  void run(const Image& color, const Image*, const Image* next, std::vector<Image>& out, MorphTimings& t) override {
    const auto t0 = std::chrono::steady_clock::now();
    const std::size_t np = color.pixel_count();
    const int n = int(out.size());
    for (const char* ch : kRGB) std::copy(color.plane(ch), color.plane(ch) + np, out[0].plane(ch));
    for (int k = 1; k < n; ++k) {
      const float a = float(k) / float(n);
      for (const char* ch : kRGB) {
        float* d = out[std::size_t(k)].plane(ch);
        const float* p = color.plane(ch);
        const float* q = next ? next->plane(ch) : p;
        parallel_chunks(np, [&](std::size_t i0, std::size_t i1) {
          for (std::size_t i = i0; i < i1; ++i) d[i] = (1.0f - a) * p[i] + a * q[i];
        });
      }
    }
    t.morph_ms = ms_since(t0);
  }
};

}  // namespace

const MethodEntry& blend_method() {
  static const MethodEntry entry{
      .info = {.name = "blend",
               .summary = "linear-light blend of frames n and n+1 (sees the next frame: one rendered frame of latency)",
               .latency_frames = 1},
      .layers = [](const MorphOptions&) { return std::vector<LayerNeed>{}; },
      .implementations = {{kCpuDevice, [](const MorphOptions&) -> std::unique_ptr<MorphMethod> {
                             return std::make_unique<Blend>();
                           }},
                          {kGpuDevice, make_blend_method_gpu}},
      .lookahead = 1,
  };
  return entry;
}

}  // namespace temporal::morph
