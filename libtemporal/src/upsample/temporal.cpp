// `temporal`: temporally-amortised upsampling, seed 000 section 3.2, eq. 4 with the binary weight w_t:
// a pixel shaded this frame (w_t = 1) takes the new sample, every other pixel takes the previous output at
// its motion-compensated position. Disocclusions (warped depth + material id, Figure 3) and pixels that
// leave the screen have no history: the paper re-renders them in a second pass; we count them
// (FrameStats::hole_pixels, `temporal:holePixels`) and fill them with the joint-bilateral result (eq. 1-3).
#include "method.h"
#include "gpu_methods.h"

#include "temporal/core/isa.h"
#include "temporal/core/parallel.h"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstring>

namespace temporal::upsample {

namespace {

// The copies, one per instruction set (temporal/core/isa.h); a state runs the copy of the level active when it
// was made. Its frame code only selects and copies: the copies give the same values.
#define TEMPORAL_ISA_FILE "temporal_impl.inc"
#include "temporal/core/isa_copies.inc"

std::unique_ptr<MethodState> make_state(const Options&, const Geometry& g) {
  TEMPORAL_ISA_CALL(copy, return std::make_unique<copy::TemporalState>(g))
}

// depth + N, payload in and out; motion, id; the previous depth and id read and written; the history read.
std::size_t streamed_bytes(const Options&, int W, int H, int k, int C) {
  const std::size_t full = std::size_t(W) * H * 4, low = full / (std::size_t(k) * k);
  return 4 * full + C * low + C * full + 2 * full + full + 2 * (2 * full) + C * full;
}

}  // namespace

const MethodEntry& temporal_method() {
  static const MethodEntry entry{
      .info = {.name = "temporal",
               .summary = "temporally-amortised upsampling (seed 000 section 3.2, eq. 4): new samples kept, the "
                          "previous output at p + motion elsewhere, holes filled spatially",
               .has_state = true},
      .layers = history_method_layers,
      .implementations = {{kCpuDevice, make_state},
                          // temporal_gpu.cpp: eq. 4 as one GLSL kernel, the same state planes.
                          {kGpuDevice, gpu_implementation<make_temporal_state_gpu>}},
      .streamed_bytes = streamed_bytes};
  return entry;
}

}  // namespace temporal::upsample
