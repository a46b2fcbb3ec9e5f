// TAA after Karis 2014 (the UE4-TAA baseline of seed 003 Table 2). Choices beyond the talk are listed in
// docs/filter-phlm.md ("TAA").
#include "temporal/phlm/taa.h"

#include "filter_common.h"
#include "temporal/core/color.h"
#include "temporal/core/parallel.h"
#include "temporal/core/reproject.h"

#include <algorithm>
#include <atomic>
#include <cmath>

namespace temporal {
namespace {

// Plain comparisons instead of std::fmin / std::fmax: those honour NaN operands and are not inlined by GCC
// (a libm call per use, measured 11% of the PHLM frame); every operand here is finite.
inline float min_(float a, float b) { return b < a ? b : a; }
inline float max_(float a, float b) { return a < b ? b : a; }


template <int C>
inline void to_box(const float* v, float* b) {
  if constexpr (C == 3)
    rgb_to_ycgco(v[0], v[1], v[2], b[0], b[1], b[2]);
  else
    b[0] = v[0];
}
template <int C>
inline void from_box(const float* b, float* v) {
  if constexpr (C == 3)
    ycgco_to_rgb(b[0], b[1], b[2], v[0], v[1], v[2]);
  else
    v[0] = b[0];
}

template <int C>
void run_taa(const FilterInput& in, const TaaParams& params, bool have_history, const float* const hist[C],
             float* const next[C], const float* const box[C], const std::uint8_t* valid, float* const out[C],
             float* dbg_clip, float* dbg_nohist, std::atomic<std::size_t>& resets, std::atomic<std::size_t>& clips) {
  const int w = in.color->width(), h = in.color->height();
  const float* y[C];
  for (int c = 0; c < C; ++c) y[c] = in.color->plane(in.channels[std::size_t(c)]);
  // Reconstruction weights of the 3x3 samples: sample (dx, dy) was taken at (dx + jx, dy + jy) from the
  // centre of the current pixel (docs/conventions.md, Jitter); Karis' Blackman-Harris fit exp(-2.29 d^2).
  float weight[9];
  for (int j = 0; j < 3; ++j)
    for (int k = 0; k < 3; ++k) {
      const float dx = float(k - 1) + in.jitter.x, dy = float(j - 1) + in.jitter.y;
      weight[j * 3 + k] = std::exp(-params.filter_sharpness * (dx * dx + dy * dy));
    }
  const float alpha = params.alpha;
  parallel_rows(h, [&](int y0, int y1) {
    std::size_t local_resets = 0, local_clips = 0;
    for (int yy = y0; yy < y1; ++yy) {
      const int rows[3] = {std::max(yy - 1, 0), yy, std::min(yy + 1, h - 1)};
      for (int xx = 0; xx < w; ++xx) {
        const std::size_t i = std::size_t(yy) * std::size_t(w) + std::size_t(xx);
        const int cols[3] = {std::max(xx - 1, 0), xx, std::min(xx + 1, w - 1)};
        float bmin[C], bmax[C], cur[C];
        for (int c = 0; c < C; ++c) {
          bmin[c] = INFINITY;
          bmax[c] = -INFINITY;
          cur[c] = 0.0f;
        }
        float wsum = 0.0f;
        for (int j = 0; j < 3; ++j)
          for (int k = 0; k < 3; ++k) {
            const std::size_t n = std::size_t(rows[j]) * std::size_t(w) + std::size_t(cols[k]);
            if (!valid[n]) continue;
            const float wt = weight[j * 3 + k];
            wsum += wt;
            for (int c = 0; c < C; ++c) {
              bmin[c] = min_(bmin[c], box[c][n]);
              bmax[c] = max_(bmax[c], box[c][n]);
              cur[c] += wt * y[c][n];
            }
          }
        const bool any_valid = wsum > 0.0f;
        for (int c = 0; c < C; ++c) cur[c] = any_valid ? cur[c] / wsum : 0.0f;

        const float mvx = in.motion_x ? in.motion_x[i] : 0.0f;
        const float mvy = in.motion_y ? in.motion_y[i] : 0.0f;
        const float fx = float(xx) + mvx, fy = float(yy) + mvy;
        const bool no_history = in.reset || !have_history || !reproject::on_screen(fx, fy, w, h);
        float result[C];
        float clipped = 0.0f;
        if (no_history) {
          for (int c = 0; c < C; ++c) result[c] = cur[c];
          ++local_resets;
        } else {
          const reproject::CatmullRom cr = reproject::catmull_rom(fx, fy, w, h);
          float hv[C];
          for (int c = 0; c < C; ++c) hv[c] = cr(hist[c]);
          if (!any_valid) {
            for (int c = 0; c < C; ++c) result[c] = hv[c];  // nothing valid to blend in: keep the history
          } else {
            // Clip the history towards the filtered current colour (inside the box: it is a convex
            // combination of the box's samples) in YCgCo.
            float hb[C], cb[C];
            to_box<C>(hv, hb);
            to_box<C>(cur, cb);
            float t = 1.0f;
            for (int c = 0; c < C; ++c) {
              const float d = hb[c] - cb[c];
              if (d > 0.0f && cb[c] + d > bmax[c]) t = min_(t, max_(bmax[c] - cb[c], 0.0f) / d);
              if (d < 0.0f && cb[c] + d < bmin[c]) t = min_(t, min_(bmin[c] - cb[c], 0.0f) / d);
            }
            if (t < 1.0f) {
              for (int c = 0; c < C; ++c) hb[c] = cb[c] + t * (hb[c] - cb[c]);
              from_box<C>(hb, hv);
              clipped = 1.0f;
              ++local_clips;
            }
            // Exponential blend with Karis' luminance weights 1 / (1 + Y) (anti-flicker for HDR values).
            const float lc = max_(cb[0], 0.0f), lh = max_(hb[0], 0.0f);
            const float wc = alpha / (1.0f + lc), wh = (1.0f - alpha) / (1.0f + lh);
            const float inv = 1.0f / (wc + wh);
            for (int c = 0; c < C; ++c) result[c] = (wc * cur[c] + wh * hv[c]) * inv;
          }
        }
        for (int c = 0; c < C; ++c) {
          out[c][i] = result[c];
          next[c][i] = result[c];
        }
        if (dbg_clip) {
          dbg_clip[i] = clipped;
          dbg_nohist[i] = no_history ? 1.0f : 0.0f;
        }
      }
    }
    resets += local_resets;
    clips += local_clips;
  });
}

}  // namespace

TaaFilter::TaaFilter(TaaParams params) : params_(params) {}

std::vector<std::string> TaaFilter::state_channel_names(int channels) {
  return detail::history_channel_names(channels);
}

Status TaaFilter::process(const FilterInput& in, Image& output, FilterStats* stats) {
  if (Status s = validate_filter_input(in); !s) return s;
  const int channels = int(in.channels.size());
  const int w = in.color->width(), h = in.color->height();
  const bool same = have_state_ && channels == channels_ && history_.width() == w && history_.height() == h;
  if (!same) {
    channels_ = channels;
    detail::allocate_history(history_, next_, channels, w, h);
  }
  const std::size_t non_finite = detail::prepare_frame(in, channels == 3, ycgco_, valid_);
  float* out[3] = {};
  detail::prepare_output(in, output, out);
  float* dbg_clip = in.debug ? output.add_channel("debug.clip") : nullptr;
  float* dbg_nohist = in.debug ? output.add_channel("debug.noHistory") : nullptr;
  const auto names = state_channel_names(channels);
  const float* hist[3] = {};
  float* next[3] = {};
  const float* box[3] = {};
  for (int c = 0; c < channels; ++c) {
    hist[c] = history_.plane(names[std::size_t(c)]);
    next[c] = next_.plane(names[std::size_t(c)]);
    box[c] = channels == 3 ? ycgco_[c].data() : in.color->plane(in.channels[0]);
  }
  std::atomic<std::size_t> resets{0}, clips{0};
  if (channels == 3)
    run_taa<3>(in, params_, same, hist, next, box, valid_.data(), out, dbg_clip, dbg_nohist, resets, clips);
  else
    run_taa<1>(in, params_, same, hist, next, box, valid_.data(), out, dbg_clip, dbg_nohist, resets, clips);
  std::swap(history_, next_);
  have_state_ = true;
  if (stats) {
    *stats = {};
    stats->non_finite = non_finite;
    stats->history_resets = resets.load();
    stats->clamped = clips.load();
  }
  return Status::ok();
}

Status TaaFilter::set_state(const Image& state, int channels) {
  if (Status s = detail::load_history(state, channels, "taa", history_, next_); !s) return s;
  channels_ = channels;
  have_state_ = true;
  return Status::ok();
}

}  // namespace temporal
