// The GPU implementations of morph-120hz's methods (GLSL compute kernels, temporal/gpu): each factory returns the
// same MorphMethod as the method's registry entry (methods.h) and runs the same algorithm; the morph methods keep
// no state between rendered frames. The objects also implement gpu::TimedKernel (their kernels' time for one
// rendered frame, all slots). Tolerances against the C++ reference: docs/gpu.md.
#pragma once

#include "temporal/core/error.h"
#include "temporal/gpu/context.h"
#include "temporal/morph/methods.h"

#include <memory>

namespace temporal::morph {

// `blend` (blend.cpp): slot k = (1 - k/N) frame n + (k/N) frame n+1.
Expected<std::unique_ptr<MorphMethod>> make_blend_method_gpu(std::shared_ptr<gpu::Context> context,
                                                             const MorphOptions& options);
// `warp` (warp.cpp): forward splat along the motion with a depth test, holes black.
Expected<std::unique_ptr<MorphMethod>> make_warp_method_gpu(std::shared_ptr<gpu::Context> context,
                                                            const MorphOptions& options);

}  // namespace temporal::morph
