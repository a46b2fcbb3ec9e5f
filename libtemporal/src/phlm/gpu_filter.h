// What filter-phlm's GPU filters share (ema_gpu.cpp, taa_gpu.cpp, phlm_gpu.cpp, fxaa_gpu.cpp), so that each of them
// holds only its kernel, its buffers and its uniforms: the context, the counters their kernels count into (binding
// 15, gpu::glsl::prelude's count_add), the timer and the last frame's timing (gpu::TimedKernel); the frame's colour
// and motion planes, which every filter's `src` buffer starts with; the output planes read back; and the kernels
// compiled once per channel count.
#pragma once

#include "filter_common.h"
#include "temporal/gpu/buffer.h"
#include "temporal/gpu/context.h"
#include "temporal/gpu/glsl.h"
#include "temporal/gpu/program.h"
#include "temporal/gpu/timer.h"

#include <initializer_list>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace temporal::phlm::detail {

class GpuFilter : public FrameFilter, public gpu::TimedKernel {
 public:
  gpu::KernelTiming last_timing() const final { return timing_; }

 protected:
  GpuFilter(std::shared_ptr<gpu::Context> ctx, gpu::ImageBuffer counters)
      : ctx_(std::move(ctx)), counters_(std::move(counters)), timer_(ctx_) {}

  // The frame's C filtered channels into planes 0..C-1 of `src`, and with `motion` its motion (when the frame has
  // any) into planes C and C+1: the first planes of every filter's `src` buffer.
  static Status upload_colour(const FilterInput& in, gpu::ImageBuffer& src, bool motion) {
    const int C = int(in.channels.size());
    for (int c = 0; c < C; ++c)
      if (Status s = src.upload(c, *in.color, in.channels[std::size_t(c)]); !s) return s;
    if (motion && in.motion_x) {
      if (Status s = src.upload(C, in.motion_x); !s) return s;
      if (Status s = src.upload(C + 1, in.motion_y); !s) return s;
    }
    return Status::ok();
  }

  // The frame's dispatches (`dispatch()`, which returns their Status) with the counters bound and between the timer's
  // start and stop: timing_'s kernel_ms and clock (the filter adds bytes_moved, which only it knows).
  template <class Dispatch>
  Status timed(Dispatch dispatch) {
    counters_.bind(15);
    timer_.start();
    if (Status s = dispatch(); !s) return s;
    timing_.kernel_ms = timer_.stop_ms();
    timing_.clock = timer_.clock();
    return Status::ok();
  }

  // The output: the filtered channels (prepare_output) from planes 0..C-1 of `buf`, and with in.debug the planes
  // `debug_names` from `first_debug` on.
  static Status download_output(const FilterInput& in, Image& output, const gpu::ImageBuffer& buf, int first_debug,
                                std::span<const char* const> debug_names) {
    float* out[3] = {};
    prepare_output(in, output, out);
    for (int c = 0; c < int(in.channels.size()); ++c)
      if (Status s = buf.download(c, out[c]); !s) return s;
    if (in.debug)
      for (std::size_t d = 0; d < debug_names.size(); ++d)
        if (Status s = buf.download(first_debug + int(d), output.add_channel(debug_names[d])); !s) return s;
    return Status::ok();
  }

  std::shared_ptr<gpu::Context> ctx_;
  gpu::ImageBuffer counters_;
  gpu::Timer timer_;
  gpu::KernelTiming timing_;
};

// A kernel built twice, for one channel (programs[0]) and for three (programs[1]): the prelude, then
// "#define <macro> 1|3" and "#define BOX_C <macro>" (gpu::glsl::ycgco_box's channel count), then `parts`. With the
// channel count a compile-time constant the kernel's per-channel arrays stay in registers. The programs are named
// "<name> (1 channel)" and "<name> (3 channels)" in a compile error.
inline Status compile_per_channel_count(const std::shared_ptr<gpu::Context>& context, const std::string& name,
                                        const std::string& macro, std::initializer_list<std::string_view> parts,
                                        gpu::Program (&programs)[2]) {
  for (int k = 0; k < 2; ++k) {
    const std::string define = "#define " + macro + (k == 0 ? " 1" : " 3") + "\n#define BOX_C " + macro + "\n";
    std::vector<std::string_view> source = {gpu::glsl::prelude(), define};
    source.insert(source.end(), parts.begin(), parts.end());
    auto program = gpu::Program::compile(context, name + (k == 0 ? " (1 channel)" : " (3 channels)"), source);
    if (!program) return program.error();
    programs[k] = std::move(*program);
  }
  return Status::ok();
}

}  // namespace temporal::phlm::detail
