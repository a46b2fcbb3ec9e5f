// Temporal antialiasing after Karis, "High-quality temporal supersampling" (SIGGRAPH 2014 course), the
// UE4-TAA baseline of seed 003 Table 2.
//
// Per pixel and frame:
//  1. Current colour: the 3x3 jittered input samples filtered with Karis' Blackman-Harris approximation
//     w = exp(-2.29 d^2), d the distance from the pixel centre to each sample (the input's `temporal:jitter`
//     says where the samples were taken), which removes the jitter from the current colour.
//  2. History: the previous output fetched at p + motion with a 4x4 Catmull-Rom filter (temporal/phlm/resample.h);
//     off-screen: no history.
//  3. Neighbourhood clipping in YCoCg: the history is clipped to the min/max box of the 3x3 input samples,
//     along the segment towards the filtered current colour (which always lies inside the box).
//  4. Blend: exponential, current weight `alpha` (0.04), with Karis' luminance weighting 1 / (1 + Y) of both
//     terms against HDR flicker.
// NaN/Inf input samples are left out of the filter and the box; a pixel with no finite sample keeps its
// history.
#pragma once

#include "temporal/core/error.h"
#include "temporal/phlm/frame_filter.h"
#include "temporal/core/image.h"

#include <cstdint>
#include <string>
#include <vector>

namespace temporal {

struct TaaParams {
  float alpha = 0.04f;            // weight of the current frame in the exponential blend
  float filter_sharpness = 2.29f; // Blackman-Harris approximation exp(-k d^2)
};

class TaaFilter final : public FrameFilter {
 public:
  explicit TaaFilter(TaaParams params = {});

  // Filters one frame; `debug.clip` (1 where the history was clipped) and `debug.noHistory` (1 off-screen or
  // reset) are added when in.debug.
  Status process(const FilterInput& in, Image& output, FilterStats* stats = nullptr) override;

  // History (the last output), planes `history.<c>`, for --state-out / --state-in.
  const Image& state() const { return history_; }
  Status set_state(const Image& state, int channels) override;
  Image saved_state() const override { return history_; }
  static std::vector<std::string> state_channel_names(int channels);

 private:
  TaaParams params_;
  Image history_;
  Image next_;
  int channels_ = 0;
  bool have_state_ = false;
  std::vector<float> ycgco_[3];     // this frame's input in YCgCo (reused)
  std::vector<std::uint8_t> valid_;  // 1 where the input pixel is finite
};

}  // namespace temporal
