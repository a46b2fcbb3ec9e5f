// Helpers shared by the filters of src/phlm (not part of the public headers).
#pragma once

#include "temporal/phlm/frame_filter.h"
#include "temporal/phlm/taa.h"
#include "temporal/core/color.h"

#include <cstdint>
#include <string>
#include <vector>

namespace temporal::phlm::detail {

// Marks the finite pixels of the input (valid = 1 when every filtered channel is finite) and, when
// `want_ycgco`, converts the three channels to YCgCo planes (temporal/core/color.h). Buffers are resized only
// when the frame size changes. Returns the number of non-finite pixels.
std::size_t prepare_frame(const FilterInput& in, bool want_ycgco, std::vector<float> ycgco[3],
                          std::vector<std::uint8_t>& valid);

// Sizes `output` like the input (reusing its planes when it already matches), adds the filtered channels
// with the input's names and returns their planes in `out`.
void prepare_output(const FilterInput& in, Image& output, float* out[3]);

// Suffix of channel c in state and debug layer names: R, G, B for three channels, Y for one.
const char* channel_suffix(int channels, int c);

// `history.R/G/B` (or `history.Y`): the state planes of the single-history filters (TAA, EMA).
std::vector<std::string> history_channel_names(int channels);

// Makes `history` and `next` width x height images holding the history planes of `channels` channels.
void allocate_history(Image& history, Image& next, int channels, int width, int height);

// Loads the history planes of a state image written by `--state-out` into `history` (and sizes `next` to
// match), refusing a missing or non-finite plane. `method` names the method in the messages.
Status load_history(const Image& state, int channels, const char* method, Image& history, Image& next);

// The resolved choices of TaaParams (shared by the C++ and GPU TAA).
struct TaaConfig {
  float alpha = 0.0f, gamma = 1.0f;
  TaaVelocity velocity = TaaVelocity::Nearest;
  TaaClip clip = TaaClip::MinMax;
  HistoryFetch history = HistoryFetch::CatmullRom;
};
// Checks and resolves TaaParams (usage errors name the flag).
Expected<TaaConfig> resolve_taa(const TaaParams& p);
// The frame-dependent check: `nearest` velocity needs depth when there is motion (a usage error naming the fix).
Status check_taa_input(const TaaConfig& cfg, const FilterInput& in);
// to_ycgco_box / from_ycgco_box (temporal/core/color.h) for C = 1 or 3 channels, always inlined: phlm's and taa's
// pixel kernels are compiled once per instruction set (temporal/core/isa.h), and with three callers GCC stopped
// inlining the generic functions (an out-of-line call per pixel, compiled for the baseline, in every copy). The
// same operations in the same order.
template <int C>
[[gnu::always_inline]] inline void to_box(const float* in, float* out) {
  if constexpr (C == 3)
    rgb_to_ycgco(in[0], in[1], in[2], out[0], out[1], out[2]);
  else
    out[0] = in[0];
}
template <int C>
[[gnu::always_inline]] inline void from_box(const float* in, float* out) {
  if constexpr (C == 3)
    ycgco_to_rgb(in[0], in[1], in[2], out[0], out[1], out[2]);
  else
    out[0] = in[0];
}

}  // namespace temporal::phlm::detail
