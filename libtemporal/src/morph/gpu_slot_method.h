// What the GPU morph methods that compute the in-between slots one after the other share (blend_gpu.cpp,
// warp_gpu.cpp; not installed): run() timed as a whole on the host (MorphTimings::morph_ms, the uploads and
// downloads included, as the C++ methods' morph_ms), the call's status (run() itself cannot return an error: the
// caller asks run_status()), and the kernels' timing summed over the slots. didyk_gpu.cpp does not use it: its run()
// reads flow, morph and blur times from its GPU timer.
#pragma once

#include "method_common.h"
#include "temporal/core/error.h"
#include "temporal/core/image.h"
#include "temporal/gpu/buffer.h"
#include "temporal/gpu/context.h"
#include "temporal/gpu/timer.h"
#include "temporal/morph/methods.h"

#include <algorithm>
#include <chrono>
#include <memory>
#include <vector>

namespace temporal::morph::detail {

class GpuSlotMethod : public MorphMethod, public gpu::TimedKernel {
 public:
  void run(const Image& color, const Image* gbuffer, const Image* next, std::vector<Image>& out,
           MorphTimings& t) final {
    const auto t0 = std::chrono::steady_clock::now();
    status_ = run_gpu(color, gbuffer, next, out);
    t.morph_ms = ms_since(t0);
  }
  Status run_status() const final { return status_; }
  gpu::KernelTiming last_timing() const final { return timing_; }

 protected:
  explicit GpuSlotMethod(std::shared_ptr<gpu::Context> ctx) : ctx_(std::move(ctx)), timer_(ctx_) {}
  // The method's run(), with its inputs uploaded, begin_slots(), and each slot from 1 on computed and downloaded.
  virtual Status run_gpu(const Image& color, const Image* gbuffer, const Image* next, std::vector<Image>& out) = 0;

  // Slot 0 is frame n itself (its R, G, B copied, as the C++ methods do), and the kernels' time starts from 0: the
  // slots add theirs.
  void begin_slots(const Image& color, std::vector<Image>& out) {
    const std::size_t np = color.pixel_count();
    for (int c = 0; c < 3; ++c) std::copy(color.plane(kRGB[c]), color.plane(kRGB[c]) + np, out[0].plane(kRGB[c]));
    timing_ = {};
    timing_.clock = timer_.clock();
  }

  // A slot's R, G, B from planes 0-2 of `slot`.
  static Status download_slot(const gpu::ImageBuffer& slot, Image& out) {
    for (int c = 0; c < 3; ++c)
      if (Status s = slot.download(c, out.plane(kRGB[c])); !s) return s;
    return Status::ok();
  }

  std::shared_ptr<gpu::Context> ctx_;
  gpu::Timer timer_;
  Status status_;
  gpu::KernelTiming timing_;
};

}  // namespace temporal::morph::detail
