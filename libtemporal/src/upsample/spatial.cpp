// `spatial`: joint-bilateral upsampling, seed 000 section 3.1 (eq. 1-3) with the hat image kernel of
// [Yang et al. 2008]. Whole frames read the two low rows of each full row expanded to full-resolution columns
// (ExpandedLowRows, shared with herzog's pass A): unit-stride loads instead of ~32 gathers per pixel. The
// gathering version (spatial_row, in frame.cpp) serves `temporal`'s sparse hole runs; both compute the
// same weights in the same order, so their results are bit-identical.
#include "method.h"
#include "gpu_methods.h"

#include "temporal/core/isa.h"
#include "temporal/core/parallel.h"

#include <immintrin.h>

#include <cstdint>
#include <cstring>

namespace temporal::upsample {
namespace {

// The copies, one per instruction set (temporal/core/isa.h); a state runs the copy of the level active when it
// was made. v3 and v4 may contract the weighted sums into FMAs (v2 has none): v2 differs in the last bits.
#define TEMPORAL_ISA_FILE "spatial_impl.inc"
#include "temporal/core/isa_copies.inc"

std::unique_ptr<MethodState> make_state(const Options&, const Geometry& g) {
  TEMPORAL_ISA_CALL(copy, return std::make_unique<copy::SpatialState>(g))
}

std::vector<LayerNeed> layers(const Options&) { return {{"depth"}, {"N"}}; }

// Reads depth + N (4 planes) and the payload, writes the output; nothing else.
std::size_t streamed_bytes(const Options&, int W, int H, int k, int C) {
  const std::size_t full = std::size_t(W) * H * 4, low = full / (std::size_t(k) * k);
  return 4 * full + C * low + C * full;
}

}  // namespace

const MethodEntry& spatial_method() {
  static const MethodEntry entry{
      .info = {.name = "spatial",
               .summary = "joint-bilateral upsampling of this frame's samples (seed 000 section 3.1, eq. 1-3, hat "
                          "kernel)"},
      .layers = layers,
      .implementations = {{kCpuDevice,
                           make_state},
                          // spatial_gpu.cpp: eq. 1-3 as one GLSL kernel.
                          {kGpuDevice, gpu_implementation<make_spatial_state_gpu>}},
      .streamed_bytes = streamed_bytes};
  return entry;
}

}  // namespace temporal::upsample
