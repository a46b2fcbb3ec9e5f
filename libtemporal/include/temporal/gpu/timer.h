// Timing a kernel: GPU time from GL_TIME_ELAPSED queries where the device reports them (hardware drivers), else
// wall-clock time between two glFinish calls (llvmpipe, whose queries read 0). The result says which.
#pragma once

#include "temporal/gpu/context.h"

#include <chrono>
#include <memory>

namespace temporal::gpu {

enum class Clock { GpuQuery, WallAfterFinish };
// "gpu (GL_TIME_ELAPSED)" | "wall clock after glFinish"
const char* clock_name(Clock clock);

class Timer {
 public:
  explicit Timer(std::shared_ptr<Context> context);
  ~Timer();
  Timer(const Timer&) = delete;
  Timer& operator=(const Timer&) = delete;

  Clock clock() const;
  // Starts a measurement (with the wall clock: waits for earlier commands first, so they are not counted).
  void start();
  // Ends it and returns the milliseconds of the commands issued since start() (waits for them).
  double stop_ms();

 private:
  std::shared_ptr<Context> context_;
  unsigned query_ = 0;
  std::chrono::steady_clock::time_point begin_;
};

// What one GPU method call cost: the kernels' time (Timer), the clock it was read from, and the bytes the kernels
// read and wrote once each (each plane they touch counted once: the compulsory traffic, the streaming bound's unit).
struct KernelTiming {
  double kernel_ms = 0.0;
  Clock clock = Clock::WallAfterFinish;
  double bytes_moved = 0.0;
};

// Implemented by every GPU method beside its method interface: the timing of its last call (the benchmark and the
// tools' temporal:computeMs read it through dynamic_cast).
class TimedKernel {
 public:
  virtual ~TimedKernel() = default;
  virtual KernelTiming last_timing() const = 0;
};

}  // namespace temporal::gpu
