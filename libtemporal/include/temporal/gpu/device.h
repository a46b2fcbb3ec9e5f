// What the method stages share for `--device cpu|gpu` (docs/gpu.md, "Choosing the device"): the run's context,
// the header attributes that say where a method ran, and how its `temporal:computeMs` was measured. The
// implementation itself is chosen from the method's registry entry (temporal/core/method.h, DeviceFactory).
#pragma once

#include "temporal/core/error.h"
#include "temporal/core/stage.h"
#include "temporal/gpu/context.h"
#include "temporal/gpu/timer.h"

#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace temporal::gpu {

// The context of a run on `device`: null for "cpu"; for "gpu" a new context on the default EGL device (the first
// hardware device, else llvmpipe). A usage error naming the fix (the packages) when none can be made.
Expected<std::shared_ptr<Context>> context_for_device(std::string_view device);

// How a CPU method's computeMs is measured: std::chrono::steady_clock around the method's call, I/O excluded.
inline constexpr const char* kCpuClock = "wall clock";

// A method's time for one call: on the GPU the kernels' time (TimedKernel: GL_TIME_ELAPSED on hardware, the wall
// clock between two glFinish on llvmpipe), without the uploads and downloads around them; on the CPU, or for a GPU
// method that does not time its kernels (`kernel` null), the wall-clock time of the call.
struct ComputeTime {
  double ms = 0.0;
  std::string clock = kCpuClock;  // `temporal:computeClock`
};
ComputeTime compute_time(const TimedKernel* kernel, double wall_ms);

// Records where the method of `out` ran, in its header (docs/conventions.md): `temporal:device` (cpu | gpu),
// `temporal:computeMs` and `temporal:computeClock` from `time`, and on the GPU the context's `temporal:glContext`
// (egl), `glDevice`, `glVendor`, `glRenderer`, `glVersion` (render-gbuffer's names). On the CPU the gl* attributes an
// input's header carries (the renderer of the input) are dropped: they would claim a context this file's pixels
// were not computed in.
void record_device(StageOutput& out, const Context* context, const ComputeTime& time);

// The gl* attribute keys (without `temporal:`), as render-gbuffer writes them.
const std::vector<std::string>& gl_attribute_keys();

}  // namespace temporal::gpu
