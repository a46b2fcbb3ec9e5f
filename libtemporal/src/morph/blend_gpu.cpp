// `blend` (blend.cpp) as a GLSL compute kernel: one dispatch per in-between slot, the same expression.
#include "gpu_slot_method.h"
#include "temporal/gpu/glsl.h"
#include "temporal/gpu/program.h"
#include "temporal/morph/gpu_methods.h"

namespace temporal::morph {
namespace {

using namespace detail;

// frames (binding 0): R, G, B of frame n (planes 0-2) and of frame n+1 (3-5); outb (1): R, G, B of the slot.
constexpr const char* kBlendMain = R"(
uniform uint u_n;
uniform float u_a;
void main() {
  ivec2 p;
  uint i;
  if (!pixel_index(p, i)) return;
  for (uint c = 0u; c < 3u; ++c)
    outb[c * u_n + i] = (1.0 - u_a) * frames[c * u_n + i] + u_a * frames[(3u + c) * u_n + i];
}
)";

class BlendGpu final : public GpuSlotMethod {
 public:
  BlendGpu(std::shared_ptr<gpu::Context> ctx, gpu::Program program)
      : GpuSlotMethod(std::move(ctx)), program_(std::move(program)) {}

 private:
  Status run_gpu(const Image& color, const Image*, const Image* next_frame, std::vector<Image>& out) override {
    const Image& next = next_frame ? *next_frame : color;
    const int w = color.width(), h = color.height();
    const std::size_t np = color.pixel_count();
    if (frames_.width() != w || frames_.height() != h)
      if (Status s = gpu::ImageBuffer::create_all(ctx_, {{&frames_, w, h, 6}, {&slot_, w, h, 3}}); !s) return s;
    for (int c = 0; c < 3; ++c) {
      if (Status s = frames_.upload(c, color, kRGB[c]); !s) return s;
      if (Status s = frames_.upload(3 + c, next, kRGB[c]); !s) return s;
    }
    begin_slots(color, out);
    const int n = int(out.size());
    for (int k = 1; k < n; ++k) {
      if (Status s = program_.use(); !s) return s;
      program_.set("u_n", std::uint32_t(np));
      program_.set("u_a", float(k) / float(n));
      frames_.bind(0);
      slot_.bind(1);
      timer_.start();
      if (Status s = program_.dispatch(w, h); !s) return s;
      timing_.kernel_ms += timer_.stop_ms();
      timing_.bytes_moved += 9.0 * double(np) * 4.0;  // two frames read, one slot written
      if (Status s = download_slot(slot_, out[std::size_t(k)]); !s) return s;
    }
    return Status::ok();
  }

  gpu::Program program_;
  gpu::ImageBuffer frames_, slot_;
};

}  // namespace

Expected<std::unique_ptr<MorphMethod>> make_blend_method_gpu(std::shared_ptr<gpu::Context> context,
                                                             const MorphOptions&) {
  if (Status s = gpu::Context::ensure(context); !s) return s.error();
  auto program = gpu::Program::compile(context, "blend",
                                       {gpu::glsl::prelude(), gpu::glsl::storage(0, "frames"),
                                        gpu::glsl::storage(1, "outb"), kBlendMain});
  if (!program) return program.error();
  return std::unique_ptr<MorphMethod>(new BlendGpu(std::move(context), std::move(*program)));
}

}  // namespace temporal::morph
