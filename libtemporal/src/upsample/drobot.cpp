// `drobot`: the spatiotemporal framework of seed 002 (Drobot 2011), in the order of its "Spatiotemporal
// Coherency" list:
//   1-2. caching at the low (shading) resolution with a history buffer HB and a current buffer CB;
//   3.   CB = this frame's samples;
//   4.   HB accumulated into CB by reprojection caching (Listing 7.2: bilinear depth, cache miss when the
//        depth differs; exponential history h(t) = h(t-1) w + r (1 - w) with a running convergence);
//   5.   the per-pixel convergence factor is kept;
//   6.   CB bilaterally filtered (Listing 7.3, separable), more strongly where convergence is low;
//   7.   CB bilaterally upsampled to full resolution (Listing 7.1, precomputed bilinear weight table);
//   8.   CB becomes HB (the filtered buffer is the history: "we were switching history buffers after
//        bilateral filtering").
// `DrobotMode::Refresh` is the refresh-buffer reconstruction of Figure 7.12: a full-resolution history,
// the 1/n refresh buffer written at its pixels, and Listing 7.1 upsampling where neither has the pixel.
//
// The low-resolution samples of successive frames sit at different sub-pixel positions (the regular
// pattern). The cache stores one value per k x k block (its centre), so that, as in Figure 7.6, each frame
// adds one subset of the block's samples and a static cache is never resampled; repeated resampling of a
// jittered grid blurs it (measured: 7 px of blur at k = 4, docs/upsample-st.md).
#include "drobot_options.h"
#include "gpu_methods.h"

#include "temporal/upsample/drobot.h"
#include "temporal/core/isa.h"
#include "temporal/core/parallel.h"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <limits>
#include <thread>
#include <vector>
#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace temporal::upsample {

const DrobotOptions& drobot_options(const Options& o) { return method_options<DrobotOptions>(o.per_method, "drobot"); }

namespace {

// The frame code's copies, one per instruction set (temporal/core/isa.h); a state runs the copy of the level
// active when it was made. v3 and v4 may contract multiply-adds into FMAs (v2 has none): v2's output can differ
// from theirs in the last bits.
#define TEMPORAL_ISA_FILE "drobot_impl.inc"
#include "temporal/core/isa_copies.inc"

std::unique_ptr<MethodState> make_state(const Options& o, const Geometry& g) {
  TEMPORAL_ISA_CALL(copy, return std::make_unique<copy::DrobotState>(o, g))
}

// The history fetch's disocclusion test compares material ids unless --no-ids.
std::size_t streamed_bytes(const Options& o, int W, int H, int k, int C) {
  const std::size_t full = std::size_t(W) * H * 4, low = full / (std::size_t(k) * k);
  std::size_t b = 4 * full + C * low + C * full;  // depth + N, payload in, payload out
  if (drobot_options(o).refresh())
    b += 2 * full + full + 2 * (2 * full) + C * full;  // motion, id; previous depth and id read and written; history
  else  // motion and id at the blocks (whole cache lines: cache_grid_read_bytes); the low-resolution cache (values,
        // depth, count, id) read and written
    b += 3 * cache_grid_read_bytes(W, H, k, 64) + 2 * (C + 3) * low;
  return b;
}

// The state holds either the low-resolution cache or the full-resolution history.
std::string state_layout(const Options& o) { return "mode " + drobot_options(o).mode; }

}  // namespace

const MethodEntry& drobot_method() {
  static const MethodEntry entry{
      .info = {.name = "drobot",
               .summary = "spatiotemporal coherence framework (seed 002, Listings 7.1-7.3): low-resolution "
                          "reprojection cache with convergence, bilateral filter, bilateral upsampling",
               .has_state = true,
               .variants = {{"drobot-refresh", "drobot", {"--mode", "refresh"},
                             "the refresh-buffer reconstruction of Figure 7.12"}}},
      .make_options = OptionsOf<DrobotOptions>::make,
      .layers = history_method_layers,
      .implementations = {{kCpuDevice,
                           make_state},
                          // drobot_gpu.cpp: both modes as GLSL kernels, the same state planes.
                          {kGpuDevice, gpu_implementation<make_drobot_state_gpu>}},
      .streamed_bytes = streamed_bytes,
      .state_layout = state_layout,
      .header_name = [](const Options& o) { return "drobot-" + drobot_options(o).mode; }};
  return entry;
}

}  // namespace temporal::upsample
