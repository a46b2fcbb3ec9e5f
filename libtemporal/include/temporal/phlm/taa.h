// Temporal antialiasing at the strength engines ship it: Karis, "High-quality temporal supersampling" (SIGGRAPH
// 2014 course, UE4's TAA), with Salvi's variance clipping ("An excursion in temporal supersampling", GDC 2016).
// The engine-strength baseline of seed 003 Table 2 (docs/filter-phlm.md, "TAA" gives the source of every choice).
//
// Per pixel and frame:
//  1. Current colour: the 3x3 jittered input samples filtered with Karis' Blackman-Harris approximation
//     w = exp(-2.29 d^2), d the distance from the pixel centre to each sample (the input's `temporal:jitter`
//     says where the samples were taken), which removes the jitter from the current colour.
//  2. Velocity (`velocity`): `nearest` takes the motion of the closest surface (smallest linear depth) of the 3x3
//     neighbourhood (UE4, Karis 2014 slide "velocity": silhouettes of moving objects keep their history in the
//     background pixels around them); `centre` the pixel's own motion. `nearest` needs depth when there is motion
//     (a usage error names the fix otherwise).
//  3. History: the previous output fetched at p + velocity with a 4x4 Catmull-Rom filter (`history`, Karis 2014;
//     `bilinear` for measurements), the shared rules of temporal/core/reproject.h; off screen: no history.
//  4. Neighbourhood clipping in YCoCg (`clip`): `minmax` clips the history to the min/max box of the 3x3 input
//     samples along the segment towards the filtered current colour (UE4's HistoryClip); `variance` clips it to
//     mu +- gamma sigma of the 3x3 samples (Salvi 2016, gamma = 1) along the segment towards mu, the box centre.
//  5. Blend: exponential, current weight `alpha`, with Karis' luminance weighting 1 / (1 + Y) of both terms
//     against HDR flicker. No sharpening, no velocity-dependent alpha.
// NaN/Inf input samples are left out of the filter, the box and the moments; a pixel with no finite sample keeps
// its history.
#pragma once

#include "temporal/core/error.h"
#include "temporal/core/image.h"
#include "temporal/phlm/frame_filter.h"

#include <cstdint>
#include <string>
#include <vector>

namespace temporal::phlm {

struct TaaParams {
  // Weight of the current frame in the exponential blend. Chosen by pipelines/filter-phlm-tune.sh on the tuning
  // set of docs/filter-phlm.md (never on an evaluation scene); UE4 ships 0.04, Salvi 2016 and most later engines
  // 0.05-0.1.
  float alpha = 0.6f;
  float filter_sharpness = 2.29f;      // Blackman-Harris approximation exp(-k d^2) (Karis 2014)
  std::string velocity = "nearest";    // nearest | centre (the 3x3 closest-depth dilation, or none)
  std::string clip = "variance";       // variance | minmax (neighbourhood clipping, see above)
  float gamma = 1.0f;                  // variance clipping: box = mu +- gamma sigma (Salvi 2016: 1)
  std::string history = "catmull-rom";  // catmull-rom | bilinear (history fetch)
};

// The choices of TaaParams as checked values (process() refuses anything else with a usage error).
enum class TaaVelocity { Nearest, Centre };
enum class TaaClip { MinMax, Variance };

class TaaFilter final : public FrameFilter {
 public:
  explicit TaaFilter(TaaParams params = {});

  // Filters one frame; with in.debug adds `debug.clip` (1 where the history was clipped), `debug.noHistory`
  // (1 off-screen or reset), `debug.velocity.X/Y` (the motion used for the history fetch, pixels).
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

}  // namespace temporal::phlm
