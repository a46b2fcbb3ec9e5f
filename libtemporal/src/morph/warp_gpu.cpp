// `warp` (warp.cpp) as GLSL compute kernels. The C++ splat keeps, per target pixel, the minimum of the 64-bit key
// (depth bits << 32 | source index) with an atomic minimum; GLSL 4.50 has no 64-bit atomics, so the same minimum
// is taken in two 32-bit passes: the smallest depth bits per target (atomicMin), then the smallest source index
// among the sources with exactly those depth bits (atomicMin). The lexicographic minimum of (depth, index) is the
// minimum of the 64-bit key, so the winner is the same source pixel.
#include "gpu_slot_method.h"
#include "temporal/gpu/glsl.h"
#include "temporal/gpu/program.h"
#include "temporal/morph/gpu_methods.h"

#include <algorithm>

namespace temporal::morph {
namespace {

using namespace detail;

// src (binding 0): R, G, B, motion.X, motion.Y, depth.Z (planes 0-5); keys (1): per target pixel the winning
// depth bits (plane 0) and source index (plane 1); outb (2): R, G, B of the slot.
constexpr const char* kWarpCommon = R"(
uniform uint u_n;
uniform float u_t;
uniform int u_pass;  // 0: depth minimum, 1: index minimum among equal depths, 2: resolve
const uint kEmpty = 0xffffffffu;

// warp.cpp's splat target of source pixel p: false off screen; `q` the target, `zbits` the depth's bits (a
// negative or NaN depth counts as FLT_MAX).
bool splat_target(ivec2 p, uint i, out uint q, out uint zbits) {
  const float fx = float(p.x) + 0.5 - u_t * src[3u * u_n + i], fy = float(p.y) + 0.5 - u_t * src[4u * u_n + i];
  if (!(fx >= 0.0 && fy >= 0.0 && fx < float(u_size.x) && fy < float(u_size.y))) return false;
  float z = src[5u * u_n + i];
  if (!(z >= 0.0)) z = uintBitsToFloat(0x7f7fffffu);
  zbits = floatBitsToUint(z);
  q = uint(int(fy)) * uint(u_size.x) + uint(int(fx));
  return true;
}
)";
constexpr const char* kWarpMain = R"(
void main() {
  ivec2 p;
  uint i;
  if (!pixel_index(p, i)) return;
  if (u_pass == 2) {
    const uint s = keys_u[u_n + i];
    const bool hole = keys_u[i] == kEmpty;
    for (uint c = 0u; c < 3u; ++c) outb[c * u_n + i] = hole ? 0.0 : src[c * u_n + s];
    return;
  }
  uint q, zbits;
  if (!splat_target(p, i, q, zbits)) return;
  if (u_pass == 0)
    atomicMin(keys_u[q], zbits);
  else if (keys_u[q] == zbits)
    atomicMin(keys_u[u_n + q], i);
}
)";

class WarpGpu final : public GpuSlotMethod {
 public:
  WarpGpu(std::shared_ptr<gpu::Context> ctx, gpu::Program program, bool debug_layers)
      : GpuSlotMethod(std::move(ctx)), program_(std::move(program)), debug_layers_(debug_layers) {}

 private:
  Status run_gpu(const Image& color, const Image* gbuffer, const Image*, std::vector<Image>& out) override {
    const Status s = splat(color, *gbuffer, out);
    // warp has no debug layer of its own: they are 0 (MorphMethod::run), whatever the kernels did.
    const std::size_t np = color.pixel_count();
    if (debug_layers_)
      for (auto& o : out)
        for (const char* ch : kMorphDebugLayers) std::fill(o.plane(ch), o.plane(ch) + np, 0.0f);
    return s;
  }

  Status splat(const Image& color, const Image& gbuffer, std::vector<Image>& out) {
    const int w = color.width(), h = color.height();
    const std::size_t np = color.pixel_count();
    if (src_.width() != w || src_.height() != h) {
      if (Status s = gpu::ImageBuffer::create_all(ctx_, {{&src_, w, h, 6}, {&keys_, w, h, 2}, {&slot_, w, h, 3}}); !s)
        return s;
      empty_.assign(np * 2, 0xffffffffu);
    }
    const char* names[6] = {"R", "G", "B", "motion.X", "motion.Y", "depth.Z"};
    for (int p = 0; p < 6; ++p)
      if (Status s = src_.upload(p, p < 3 ? color : gbuffer, names[p]); !s) return s;
    begin_slots(color, out);
    const int n = int(out.size());
    for (int k = 1; k < n; ++k) {
      // Both key planes empty (all bits set), as warp.cpp fills its buffer with kEmpty.
      if (Status s = keys_.upload(0, empty_.data()); !s) return s;
      if (Status s = keys_.upload(1, empty_.data() + np); !s) return s;
      if (Status s = program_.use(); !s) return s;
      program_.set("u_n", std::uint32_t(np));
      program_.set("u_t", float(k) / float(n));
      src_.bind(0);
      keys_.bind(1);
      slot_.bind(2);
      timer_.start();
      for (int pass = 0; pass < 3; ++pass) {
        program_.set("u_pass", pass);
        if (Status s = program_.dispatch(w, h); !s) return s;
      }
      timing_.kernel_ms += timer_.stop_ms();
      // Motion and depth read twice (two splat passes), keys written and read, the colour gathered and written.
      timing_.bytes_moved += (2.0 * 3.0 + 2.0 * 2.0 + 3.0 + 3.0) * double(np) * 4.0;
      if (Status s = download_slot(slot_, out[std::size_t(k)]); !s) return s;
    }
    return Status::ok();
  }

  gpu::Program program_;
  bool debug_layers_;
  gpu::ImageBuffer src_, keys_, slot_;
  std::vector<std::uint32_t> empty_;
};

}  // namespace

Expected<std::unique_ptr<MorphMethod>> make_warp_method_gpu(std::shared_ptr<gpu::Context> context,
                                                            const MorphOptions& options) {
  if (Status s = gpu::Context::ensure(context); !s) return s.error();
  auto program = gpu::Program::compile(context, "warp",
                                       {gpu::glsl::prelude(), gpu::glsl::storage(0, "src"),
                                        gpu::glsl::storage(1, "keys"), gpu::glsl::storage(2, "outb"), kWarpCommon,
                                        kWarpMain});
  if (!program) return program.error();
  return std::unique_ptr<MorphMethod>(new WarpGpu(std::move(context), std::move(*program), options.debug_layers));
}

}  // namespace temporal::morph
