// The history planes of filter-phlm's GPU filters that keep one (ema_gpu.cpp, taa_gpu.cpp): planes 0..C-1 of the
// history buffer are the state file's `history.<c>` (detail::history_channel_names), as the C++ filters keep them,
// so that a state written by either device resumes on the other.
#pragma once

#include "filter_common.h"
#include "temporal/gpu/buffer.h"

namespace temporal::phlm::detail {

// saved_state(): the history planes of `hist` in a state image of its size. saved_state() cannot report an error:
// a failed download leaves the plane absent, and set_state() refuses the state.
inline Image download_history(const gpu::ImageBuffer& hist, int channels) {
  Image state(hist.width(), hist.height());
  const auto names = history_channel_names(channels);
  for (int c = 0; c < channels; ++c)
    if (!hist.download(c, state, names[std::size_t(c)])) state.remove_channel(names[std::size_t(c)]);
  return state;
}

// set_state(): the history planes of `history` (checked by load_history) into `hist`.
inline Status upload_history(const Image& history, int channels, gpu::ImageBuffer& hist) {
  const auto names = history_channel_names(channels);
  for (int c = 0; c < channels; ++c)
    if (Status s = hist.upload(c, history, names[std::size_t(c)]); !s) return s;
  return Status::ok();
}

}  // namespace temporal::phlm::detail
