// `warp`: every source pixel centre of frame n is forward-splatted to p - t * motion (nearest pixel) with a depth
// test; holes stay black (no hole filling). The depth test is an atomic minimum on (depth bits << 32 | source
// index): positive floats order like their bit patterns, and the index makes the winner among equal depths
// independent of the thread schedule.
#include "method_common.h"
#include "temporal/core/isa.h"
#include "temporal/core/parallel.h"
#include "temporal/morph/gpu_methods.h"
#include "temporal/morph/methods.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstdint>
#include <limits>

namespace temporal::morph {
namespace {

using namespace detail;

constexpr std::uint64_t kWarpEmpty = std::numeric_limits<std::uint64_t>::max();  // no source pixel landed here

// The splat and resolve copies, one per instruction set (temporal/core/isa.h). v3 and v4 may contract
// x + 0.5 - t * motion into a fused multiply-add (v2 rounds the product first): a target position within rounding
// of a pixel edge can land in the neighbouring pixel (tests/core/isa_test.cpp counts them); v3 and v4 are
// bit-identical.
#define TEMPORAL_ISA_FILE "warp_kernels.inc"
#include "temporal/core/isa_copies.inc"

class Warp final : public MorphMethod {
 public:
  explicit Warp(bool debug_layers) : debug_layers_(debug_layers) {}
  void run(const Image& color, const Image* gbuffer, const Image*, std::vector<Image>& out, MorphTimings& t) override {
    const auto t0 = std::chrono::steady_clock::now();
    const int n = int(out.size());
    const std::size_t np = color.pixel_count();
    for (const char* ch : kRGB) std::copy(color.plane(ch), color.plane(ch) + np, out[0].plane(ch));
    buffer_.resize(np);
    for (int k = 1; k < n; ++k) {
      splat(color, *gbuffer, float(k) / float(n));
      resolve(color, out[std::size_t(k)]);
    }
    if (debug_layers_)
      for (auto& o : out)
        for (const char* ch : kMorphDebugLayers) std::fill(o.plane(ch), o.plane(ch) + np, 0.0f);
    t.morph_ms = ms_since(t0);
  }

 private:
  // Forward splat of each source pixel centre to p - t * motion, keeping the nearest depth per target pixel.
  void splat(const Image& color, const Image& gbuffer, float t) {
    std::fill(buffer_.begin(), buffer_.end(), kWarpEmpty);
    const float* mx = gbuffer.plane("motion.X");
    const float* my = gbuffer.plane("motion.Y");
    const float* depth = gbuffer.plane("depth.Z");
    const int w = color.width(), h = color.height();
    TEMPORAL_ISA_CALL(copy, return copy::splat(mx, my, depth, w, h, t, buffer_.data()))
  }

  // The winning source pixel of every target pixel; holes stay black.
  void resolve(const Image& color, Image& o) const {
    const float* src[3] = {color.plane("R"), color.plane("G"), color.plane("B")};
    float* dst[3] = {o.plane("R"), o.plane("G"), o.plane("B")};
    TEMPORAL_ISA_CALL(copy, return copy::resolve(buffer_.data(), src, dst, color.pixel_count()))
  }

  bool debug_layers_;
  std::vector<std::uint64_t> buffer_;
};

}  // namespace

const MethodEntry& warp_method() {
  static const MethodEntry entry{
      .info = {.name = "warp",
               .summary = "per-pixel forward splat along the motion with a depth test, holes left black",
               .latency_frames = 0},
      .layers = [](const MorphOptions&) { return std::vector<LayerNeed>{{"motion"}, {"depth"}}; },
      .implementations = {{kCpuDevice, [](const MorphOptions& o) -> std::unique_ptr<MorphMethod> {
                             return std::make_unique<Warp>(o.debug_layers);
                           }},
                          {kGpuDevice, make_warp_method_gpu}},
  };
  return entry;
}

}  // namespace temporal::morph
