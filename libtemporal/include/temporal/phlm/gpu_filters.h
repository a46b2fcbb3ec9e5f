// The GPU implementations of filter-phlm's methods (GLSL compute kernels, temporal/gpu): each factory returns the
// same FrameFilter interface as the C++ implementation, with the same state planes, so that a run started on one
// device resumes on the other from its --state-out file. The object also implements gpu::TimedKernel (the kernels'
// time of the last frame). Tolerances against the C++ reference: docs/gpu.md.
#pragma once

#include "temporal/core/error.h"
#include "temporal/gpu/context.h"
#include "temporal/phlm/ema.h"
#include "temporal/phlm/frame_filter.h"
#include "temporal/phlm/fxaa.h"
#include "temporal/phlm/phlm.h"
#include "temporal/phlm/taa.h"

#include <memory>

namespace temporal::phlm {

// The EMA filter (temporal/phlm/ema.h) on `context` (created on the default device when null).
Expected<std::unique_ptr<FrameFilter>> make_ema_filter_gpu(std::shared_ptr<gpu::Context> context,
                                                          EmaParams params = {});
// The TAA filter (temporal/phlm/taa.h) on `context` (created on the default device when null). Usage errors for
// invalid parameters, as TaaFilter::process reports them.
Expected<std::unique_ptr<FrameFilter>> make_taa_filter_gpu(std::shared_ptr<gpu::Context> context,
                                                          TaaParams params = {});

// FXAA (temporal/phlm/fxaa.h) on `context` (created on the default device when null); spatial, no state.
Expected<std::unique_ptr<FrameFilter>> make_fxaa_filter_gpu(std::shared_ptr<gpu::Context> context,
                                                           FxaaParams params = {});

// PHLM (temporal/phlm/phlm.h) on `context` (created on the default device when null). Usage errors for invalid
// parameters, as PhlmFilter::process reports them.
Expected<std::unique_ptr<FrameFilter>> make_phlm_filter_gpu(std::shared_ptr<gpu::Context> context,
                                                           PhlmParams params = {});

}  // namespace temporal::phlm
