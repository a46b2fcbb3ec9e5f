#include "temporal/gpu/device.h"

#include "temporal/core/method.h"

namespace temporal::gpu {

Expected<std::shared_ptr<Context>> context_for_device(std::string_view device) {
  if (device != kGpuDevice) return std::shared_ptr<Context>();
  return Context::create();
}

ComputeTime compute_time(const TimedKernel* kernel, double wall_ms) {
  if (!kernel) return {wall_ms, kCpuClock};
  const KernelTiming t = kernel->last_timing();
  return {t.kernel_ms, clock_name(t.clock)};
}

const std::vector<std::string>& gl_attribute_keys() {
  static const std::vector<std::string> keys = {"glContext", "glDevice", "glVendor", "glRenderer", "glVersion"};
  return keys;
}

void record_device(StageOutput& out, const Context* context, const ComputeTime& time) {
  out.compute_ms = time.ms;
  out.extra["computeClock"] = time.clock;
  out.extra["device"] = context ? kGpuDevice : kCpuDevice;
  if (!context) {
    for (const auto& k : gl_attribute_keys()) out.drop_extra.push_back(k);
    return;
  }
  out.extra["glContext"] = "egl";
  out.extra["glDevice"] = std::to_string(context->device_index());
  out.extra["glVendor"] = context->vendor();
  out.extra["glRenderer"] = context->renderer();
  out.extra["glVersion"] = context->version();
}

}  // namespace temporal::gpu
