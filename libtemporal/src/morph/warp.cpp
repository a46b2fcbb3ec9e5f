// `warp`: every source pixel centre of frame n is forward-splatted to p - t * motion (nearest pixel) with a depth
// test; holes stay black (no hole filling). The depth test is an atomic minimum on (depth bits << 32 | source
// index): positive floats order like their bit patterns, and the index makes the winner among equal depths
// independent of the thread schedule.
#include "method_common.h"
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
  static constexpr std::uint64_t kEmpty = std::numeric_limits<std::uint64_t>::max();

  // Forward splat of each source pixel centre to p - t * motion, keeping the nearest depth per target pixel.
  void splat(const Image& color, const Image& gbuffer, float t) {
    const int w = color.width(), h = color.height();
    const float* mx = gbuffer.plane("motion.X");
    const float* my = gbuffer.plane("motion.Y");
    const float* depth = gbuffer.plane("depth.Z");
    std::fill(buffer_.begin(), buffer_.end(), kEmpty);
    parallel_rows(h, [&](int y0, int y1) {
      for (int y = y0; y < y1; ++y) {
        for (int x = 0; x < w; ++x) {
          const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
          const float fx = float(x) + 0.5f - t * mx[i], fy = float(y) + 0.5f - t * my[i];
          if (!(fx >= 0.0f && fy >= 0.0f && fx < float(w) && fy < float(h))) continue;
          float z = depth[i];
          if (!(z >= 0.0f)) z = std::numeric_limits<float>::max();
          const std::uint64_t key = (std::uint64_t(std::bit_cast<std::uint32_t>(z)) << 32) | std::uint64_t(i);
          const std::size_t q = std::size_t(int(fy)) * std::size_t(w) + std::size_t(int(fx));
          std::atomic_ref<std::uint64_t> slot(buffer_[q]);
          std::uint64_t cur = slot.load(std::memory_order_relaxed);
          while (key < cur && !slot.compare_exchange_weak(cur, key, std::memory_order_relaxed)) {
          }
        }
      }
    });
  }

  // The winning source pixel of every target pixel; holes stay black.
  void resolve(const Image& color, Image& o) const {
    const float* src[3] = {color.plane("R"), color.plane("G"), color.plane("B")};
    float* dst[3] = {o.plane("R"), o.plane("G"), o.plane("B")};
    parallel_chunks(color.pixel_count(), [&](std::size_t i0, std::size_t i1) {
      for (std::size_t i = i0; i < i1; ++i) {
        const std::uint64_t key = buffer_[i];
        const bool hole = key == kEmpty;
        const std::size_t s = std::size_t(key & 0xffffffffu);
        for (int c = 0; c < 3; ++c) dst[c][i] = hole ? 0.0f : src[c][s];
      }
    });
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
