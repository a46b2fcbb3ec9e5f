// `blend`: slot k = (1 - k/N) frame n + (k/N) frame n+1 in linear light. It needs frame n+1 before slot 1 of n
// can be shown: one rendered frame of added latency. The last frame, without a successor, is repeated.
#include "method_common.h"
#include "temporal/core/isa.h"
#include "temporal/core/parallel.h"
#include "temporal/morph/gpu_methods.h"
#include "temporal/morph/methods.h"

#include <algorithm>

namespace temporal::morph {
namespace {

using namespace detail;

// The interpolation copies, one per instruction set (temporal/core/isa.h). v3 and v4 contract (1 - a) p + a q
// into a fused multiply-add (v2 has none): v2 differs from them in the last bit (tests/core/isa_test.cpp); v3 and
// v4 are bit-identical.
#define TEMPORAL_ISA_FILE "blend_kernels.inc"
#include "temporal/core/isa_copies.inc"

void lerp_plane_copy(const float* p, const float* q, float* d, std::size_t np, float a) {
  TEMPORAL_ISA_CALL(copy, return copy::lerp_plane(p, q, d, np, a))
}

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
        lerp_plane_copy(p, q, d, np, a);
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
