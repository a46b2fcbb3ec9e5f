// `repeat`: every slot shows rendered frame n, as a 40 Hz stream looks on a 120 Hz hold-type display.
#include "method_common.h"
#include "temporal/morph/methods.h"

#include <algorithm>

namespace temporal::morph {
namespace {

using namespace detail;

class Repeat final : public MorphMethod {
 public:
  void run(const Image& color, const Image*, const Image*, std::vector<Image>& out, MorphTimings& t) override {
    const auto t0 = std::chrono::steady_clock::now();
    const std::size_t np = color.pixel_count();
    for (auto& o : out)
      for (const char* ch : kRGB) std::copy(color.plane(ch), color.plane(ch) + np, o.plane(ch));
    t.morph_ms = ms_since(t0);
  }
};

}  // namespace

const MethodEntry& repeat_method() {
  static const MethodEntry entry{
      .info = {.name = "repeat",
               .summary = "every slot shows the rendered frame (the low rate held on a high-rate display)",
               .latency_frames = 0},
      .layers = [](const MorphOptions&) { return std::vector<LayerNeed>{}; },
      .implementations = {{kCpuDevice, [](const MorphOptions&) -> std::unique_ptr<MorphMethod> {
                             return std::make_unique<Repeat>();
                           }}},
  };
  return entry;
}

}  // namespace temporal::morph
