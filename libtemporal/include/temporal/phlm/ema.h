// The plain exponential history buffer of seed 003 eq. 1, with reprojection and G-buffer rejection:
//   h(t) = alpha h(t-1)(p + motion) + (1 - alpha) y(t)
// alpha is the history weight. The history is fetched at p + motion with the shared reprojection rules
// (temporal/core/reproject.h): bilinear, each tap kept only when it is the same surface (material id and depth
// within `depth_tolerance` of the larger depth); it is rejected (h = y) when the position is off screen or no tap
// survives. Without G-buffer depth and ids only the off-screen rule applies. NaN/Inf input never enters h: such
// a pixel keeps (outputs) its reprojected history.
#pragma once

#include "temporal/core/error.h"
#include "temporal/core/reproject.h"
#include "temporal/phlm/frame_filter.h"
#include "temporal/core/image.h"

#include <cstdint>
#include <string>
#include <vector>

namespace temporal::phlm {

struct EmaParams {
  float alpha = 0.5f;            // history weight of eq. 1, chosen on the tuning set (docs/filter-phlm.md)
  float depth_tolerance = reproject::kDepthTolerance;  // relative depth difference of the disocclusion test
  // The same with the warped depth (FilterInput::prev_depth), which does not change with motion along the view axis.
  float warped_depth_tolerance = reproject::kWarpedDepthTolerance;
};

class EmaFilter final : public FrameFilter {
 public:
  explicit EmaFilter(EmaParams params = {});

  // Filters one frame; `debug.reject` (1 where the history was rejected) is added when in.debug.
  Status process(const FilterInput& in, Image& output, FilterStats* stats = nullptr) override;

  // History `history.<c>` plus the previous frame's `history.depth` and `history.id` (when given).
  const Image& state() const { return history_; }
  Status set_state(const Image& state, int channels) override;
  Image saved_state() const override { return history_; }
  static std::vector<std::string> state_channel_names(int channels);

 private:
  EmaParams params_;
  Image history_;
  Image next_;
  int channels_ = 0;
  bool have_state_ = false;
  std::vector<std::uint8_t> valid_;  // 1 where the input pixel is finite
};

}  // namespace temporal::phlm
