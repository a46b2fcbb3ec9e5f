// `spatial`: joint-bilateral upsampling, seed 000 section 3.1 (eq. 1-3) with the hat image kernel of
// [Yang et al. 2008]. Whole frames read the two low rows of each full row expanded to full-resolution columns
// (ExpandedLowRows, shared with herzog's pass A): unit-stride loads instead of ~32 gathers per pixel. The
// gathering version (spatial_row, in frame.cpp) serves `temporal`'s sparse hole runs; both compute the
// same weights in the same order, so their results are bit-identical.
#include "method.h"
#include "gpu_methods.h"

#include "temporal/core/isa.h"
#include "temporal/core/parallel.h"

namespace temporal::upsample {
namespace {

// The copies, one per instruction set (temporal/core/isa.h); a state runs the copy of the level active when it
// was made. v3 and v4 may contract the weighted sums into FMAs (v2 has none): v2 differs in the last bits.
#if TEMPORAL_ISA_DISPATCH
namespace v2 {
#include "spatial_impl.inc"
}  // namespace v2
TEMPORAL_ISA_V3_BEGIN
namespace v3 {
#include "spatial_impl.inc"
}  // namespace v3
TEMPORAL_ISA_END
TEMPORAL_ISA_V4_BEGIN
namespace v4 {
#include "spatial_impl.inc"
}  // namespace v4
TEMPORAL_ISA_END
#else
namespace native {
#include "spatial_impl.inc"
}  // namespace native
#endif

std::unique_ptr<MethodState> make_state(const Options&, const Geometry& g) {
#if TEMPORAL_ISA_DISPATCH
  switch (isa::active()) {
    case isa::Level::V4: return std::make_unique<v4::SpatialState>(g);
    case isa::Level::V3: return std::make_unique<v3::SpatialState>(g);
    default: return std::make_unique<v2::SpatialState>(g);
  }
#else
  return std::make_unique<native::SpatialState>(g);
#endif
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
