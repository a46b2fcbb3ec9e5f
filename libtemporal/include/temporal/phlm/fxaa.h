// FXAA, the spatial antialiasing baseline of seed 003 Table 2, written from Lottes' description of FXAA 3.11
// "PC quality" (NVIDIA white paper, 2011): per pixel, a luma contrast test on the 4-neighbourhood (early exit
// below max(edge_threshold_min, edge_threshold * luma_max)), the edge orientation from the 3x3 second
// differences, an edge-end search along the edge in both directions (steps 1, 1, 1, 1, 1, 1.5, 2, 2, 2, 2,
// 4, 8 pixels, quality preset 12) on the bilinearly sampled luma, the sub-pixel aliasing estimate, and a
// final bilinear fetch offset perpendicular to the edge.
//
// Luma: FXAA works on perceptual luma; for scene-linear input it is sqrt of the Rec. 709 luminance of values
// clamped to [0, 1] (Lottes suggests luma in gamma space, and sqrt is the usual gamma-2 estimate).
// NaN/Inf pixels are counted and replaced by the mean of their finite 4-neighbours (0 when none is finite).
#pragma once

#include "temporal/core/error.h"
#include "temporal/phlm/frame_filter.h"
#include "temporal/core/image.h"

namespace temporal::phlm {

struct FxaaParams {
  float subpix = 0.75f;              // fxaaQualitySubpix
  float edge_threshold = 0.166f;     // fxaaQualityEdgeThreshold
  float edge_threshold_min = 0.0833f;  // fxaaQualityEdgeThresholdMin
};

// Antialiases one frame (`in.channels`; 1 or 3). `debug.edge` (1 where an edge was processed) is added when
// in.debug.
Status fxaa(const FilterInput& in, Image& output, const FxaaParams& params = {}, FilterStats* stats = nullptr);

// fxaa() as a FrameFilter: spatial, no state.
class FxaaFilter final : public FrameFilter {
 public:
  explicit FxaaFilter(FxaaParams params = {}) : params_(params) {}
  Status process(const FilterInput& in, Image& output, FilterStats* stats = nullptr) override {
    return fxaa(in, output, params_, stats);
  }
  Image saved_state() const override { return {}; }
  Status set_state(const Image&, int) override {
    return Error::usage("--method fxaa is spatial and has no state: drop --state-in / --state-out");
  }

 private:
  FxaaParams params_;
};

}  // namespace temporal::phlm
