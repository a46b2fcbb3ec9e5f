// The history of filter-phlm's GPU filters that keep one (ema_gpu.cpp, taa_gpu.cpp): planes 0..C-1 of the history
// buffer are the state file's `history.<c>` (detail::history_channel_names), as the C++ filters keep them, so that a
// state written by either device resumes on the other.
#pragma once

#include "filter_common.h"
#include "gpu_filter.h"
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

// A GPU filter with one history, as the C++ EmaFilter and TaaFilter keep theirs: `src_` the frame's planes (C + the
// filter's `src_extra` planes), `hist_` the history (the C history.<c> planes, then `history_extra` planes of the
// filter's own) and `next_` the history the frame writes (the same layout), swapped in after the frame.
class HistoryGpuFilter : public GpuFilter {
 protected:
  HistoryGpuFilter(std::shared_ptr<gpu::Context> ctx, gpu::ImageBuffer counters, int src_extra, int history_extra)
      : GpuFilter(std::move(ctx), std::move(counters)), src_extra_(src_extra), history_extra_(history_extra) {}

  // Whether a frame of `channels` channels and w x h continues the history (else it starts without one).
  bool continues_history(int channels, int w, int h) const {
    return have_state_ && channels == channels_ && hist_.width() == w && hist_.height() == h;
  }

  // The buffers for `channels` channels at w x h (kept when the size and the channel count stay).
  Status allocate(int channels, int w, int h) {
    channels_ = channels;
    if (src_.width() == w && src_.height() == h && src_.planes() == channels + src_extra_) return Status::ok();
    const int history = channels + history_extra_;
    return gpu::ImageBuffer::create_all(
        ctx_, {{&src_, w, h, channels + src_extra_}, {&hist_, w, h, history}, {&next_, w, h, history}});
  }

  // set_state()'s history: the state's history planes checked first (load_history names a missing or non-finite
  // plane, and nothing changes), the buffers made for the state's size, the planes uploaded. The filter loads its
  // own planes after it and sets have_state_.
  Status restore_history(const Image& state, int channels, const char* method) {
    Image history, next;
    if (Status s = load_history(state, channels, method, history, next); !s) return s;
    if (Status s = allocate(channels, state.width(), state.height()); !s) return s;
    return upload_history(history, channels, hist_);
  }

  gpu::ImageBuffer src_, hist_, next_;
  int channels_ = 0;
  bool have_state_ = false;

 private:
  int src_extra_, history_extra_;
};

}  // namespace temporal::phlm::detail
