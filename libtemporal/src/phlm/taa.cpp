// TAA after Karis 2014 with Salvi 2016's variance clipping (the engine-strength baseline of seed 003 Table 2).
// The source of every choice is listed in docs/filter-phlm.md ("TAA").
#include "temporal/phlm/taa.h"

#include "filter_common.h"
#include "temporal/phlm/filters.h"
#include "temporal/phlm/gpu_filters.h"
#include "temporal/core/color.h"
#include "temporal/core/minmax.h"
#include "temporal/core/parallel.h"
#include "temporal/core/reproject.h"

#include <algorithm>
#include <atomic>
#include <cmath>

namespace temporal::phlm {
namespace {

using detail::TaaConfig;

// Index of the 3x3 neighbour of pixel (xx, yy) with the smallest depth (the closest surface); the centre wins
// ties, then raster order. Non-finite depths never win.
inline std::size_t closest_neighbour(const float* depth, int xx, int yy, int w, int h) {
  const std::size_t centre = std::size_t(yy) * std::size_t(w) + std::size_t(xx);
  std::size_t best = centre;
  float bz = std::isfinite(depth[centre]) ? depth[centre] : INFINITY;
  for (int j = std::max(yy - 1, 0); j <= std::min(yy + 1, h - 1); ++j)
    for (int k = std::max(xx - 1, 0); k <= std::min(xx + 1, w - 1); ++k) {
      const std::size_t n = std::size_t(j) * std::size_t(w) + std::size_t(k);
      if (depth[n] < bz) {  // false for NaN
        bz = depth[n];
        best = n;
      }
    }
  return best;
}

// The 3x3 input samples around a pixel (edges repeat; NaN/Inf samples left out): their min/max box and first moment
// in box space (YCgCo for colour), the samples themselves for the variance, and the current colour filtered with
// Karis' reconstruction weights (step 1 of taa.h).
template <int C>
struct Neighbourhood {
  float bmin[C], bmax[C], cur[C], m1[C], samples[9][C];
  float wsum = 0.0f;
  int count = 0;
  bool any_valid() const { return wsum > 0.0f; }
};

template <int C>
Neighbourhood<C> gather_neighbourhood(const float* const y[C], const float* const box[C], const std::uint8_t* valid,
                                      const float weight[9], int xx, int yy, int w, int h) {
  Neighbourhood<C> nb;
  const int rows[3] = {std::max(yy - 1, 0), yy, std::min(yy + 1, h - 1)};
  const int cols[3] = {std::max(xx - 1, 0), xx, std::min(xx + 1, w - 1)};
  for (int c = 0; c < C; ++c) {
    nb.bmin[c] = INFINITY;
    nb.bmax[c] = -INFINITY;
    nb.cur[c] = 0.0f;
    nb.m1[c] = 0.0f;
  }
  for (int j = 0; j < 3; ++j)
    for (int k = 0; k < 3; ++k) {
      const std::size_t n = std::size_t(rows[j]) * std::size_t(w) + std::size_t(cols[k]);
      if (!valid[n]) continue;
      const float wt = weight[j * 3 + k];
      nb.wsum += wt;
      for (int c = 0; c < C; ++c) {
        const float b = box[c][n];
        nb.bmin[c] = fast_min(nb.bmin[c], b);
        nb.bmax[c] = fast_max(nb.bmax[c], b);
        nb.m1[c] += b;
        nb.samples[nb.count][c] = b;
        nb.cur[c] += wt * y[c][n];
      }
      ++nb.count;
    }
  for (int c = 0; c < C; ++c) nb.cur[c] = nb.any_valid() ? nb.cur[c] / nb.wsum : 0.0f;
  return nb;
}

// Step 3: the previous output at p + velocity with the configured filter (temporal/core/reproject.h).
template <int C>
void fetch_history(HistoryFetch fetch, const float* const hist[C], float fx, float fy, int w, int h, float* hv) {
  if (fetch == HistoryFetch::CatmullRom) {
    const reproject::CatmullRom cr = reproject::catmull_rom(fx, fy, w, h);
    for (int c = 0; c < C; ++c) hv[c] = cr(hist[c]);
  } else if (fetch == HistoryFetch::Bilinear) {
    const reproject::Bilinear bl = reproject::bilinear(fx, fy, w, h);
    for (int c = 0; c < C; ++c) hv[c] = bl(hist[c]);
  } else {
    const std::size_t q = reproject::nearest(fx, fy, w, h);
    for (int c = 0; c < C; ++c) hv[c] = hist[c][q];
  }
}

// Step 4: clips the history hb (box space) along the segment towards an origin inside the box: the filtered current
// colour cb for the min/max box (a convex combination of its samples, UE4's HistoryClip), the mean mu for the
// variance box mu +- gamma sigma (Salvi 2016). Returns true when hb was moved.
template <int C>
bool clip_history(Neighbourhood<C>& nb, const TaaConfig& cfg, const float* cb, float* hb) {
  float origin[C];
  if (cfg.clip == TaaClip::Variance) {
    // Two passes over the samples (mean, then squared deviations): identical samples give sigma = 0 exactly, where
    // E[v^2] - mu^2 would leave a rounding residue.
    const float inv_n = 1.0f / float(nb.count);
    for (int c = 0; c < C; ++c) {
      const float mu = nb.m1[c] * inv_n;
      float m2 = 0.0f;
      for (int k = 0; k < nb.count; ++k) m2 += (nb.samples[k][c] - mu) * (nb.samples[k][c] - mu);
      const float sigma = std::sqrt(m2 * inv_n);
      nb.bmin[c] = mu - cfg.gamma * sigma;
      nb.bmax[c] = mu + cfg.gamma * sigma;
      origin[c] = mu;
    }
  } else {
    for (int c = 0; c < C; ++c) origin[c] = cb[c];
  }
  float t = 1.0f;
  for (int c = 0; c < C; ++c) {
    const float d = hb[c] - origin[c];
    if (d > 0.0f && origin[c] + d > nb.bmax[c]) t = fast_min(t, fast_max(nb.bmax[c] - origin[c], 0.0f) / d);
    if (d < 0.0f && origin[c] + d < nb.bmin[c]) t = fast_min(t, fast_min(nb.bmin[c] - origin[c], 0.0f) / d);
  }
  if (t >= 1.0f) return false;
  for (int c = 0; c < C; ++c) hb[c] = origin[c] + t * (hb[c] - origin[c]);
  return true;
}

// Steps 4-5 for a pixel with history hv and at least one valid sample: the clipped history, blended exponentially
// with the current colour, with Karis' luminance weights 1 / (1 + Y) (anti-flicker for HDR values).
template <int C>
bool clip_and_blend(Neighbourhood<C>& nb, const TaaConfig& cfg, float* hv, float* result) {
  float hb[C], cb[C];
  to_ycgco_box(hv, hb, C);
  to_ycgco_box(nb.cur, cb, C);
  const bool clipped = clip_history<C>(nb, cfg, cb, hb);
  if (clipped) from_ycgco_box(hb, hv, C);
  const float lc = fast_max(cb[0], 0.0f), lh = fast_max(hb[0], 0.0f);
  const float wc = cfg.alpha / (1.0f + lc), wh = (1.0f - cfg.alpha) / (1.0f + lh);
  const float inv = 1.0f / (wc + wh);
  for (int c = 0; c < C; ++c) result[c] = (wc * nb.cur[c] + wh * hv[c]) * inv;
  return clipped;
}

// One frame of TAA (taa.h, steps 1-5) into `out` and the next history.
template <int C>
void run_taa(const FilterInput& in, const TaaParams& params, const TaaConfig& cfg, bool have_history,
             const float* const hist[C], float* const next[C], const float* const box[C], const std::uint8_t* valid,
             float* const out[C], float* const dbg[4], std::atomic<std::size_t>& resets,
             std::atomic<std::size_t>& clips) {
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
  const bool dilate = cfg.velocity == TaaVelocity::Nearest && in.motion_x && in.depth;
  parallel_rows(h, [&](int y0, int y1) {
    std::size_t local_resets = 0, local_clips = 0;
    for (int yy = y0; yy < y1; ++yy)
      for (int xx = 0; xx < w; ++xx) {
        const std::size_t i = std::size_t(yy) * std::size_t(w) + std::size_t(xx);
        Neighbourhood<C> nb = gather_neighbourhood<C>(y, box, valid, weight, xx, yy, w, h);
        // Step 2, velocity: the pixel's own motion, or that of the closest surface of the 3x3 neighbourhood.
        const std::size_t vi = dilate ? closest_neighbour(in.depth, xx, yy, w, h) : i;
        const float mvx = in.motion_x ? in.motion_x[vi] : 0.0f;
        const float mvy = in.motion_y ? in.motion_y[vi] : 0.0f;
        const float fx = float(xx) + mvx, fy = float(yy) + mvy;
        const bool no_history = in.reset || !have_history || !reproject::on_screen(fx, fy, w, h);
        float result[C];
        bool clipped = false;
        if (no_history) {
          for (int c = 0; c < C; ++c) result[c] = nb.cur[c];
          ++local_resets;
        } else {
          float hv[C];
          fetch_history<C>(cfg.history, hist, fx, fy, w, h, hv);
          if (!nb.any_valid())
            for (int c = 0; c < C; ++c) result[c] = hv[c];  // nothing valid to blend in: keep the history
          else
            clipped = clip_and_blend<C>(nb, cfg, hv, result);
          local_clips += clipped ? 1 : 0;
        }
        for (int c = 0; c < C; ++c) {
          out[c][i] = result[c];
          next[c][i] = result[c];
        }
        if (dbg[0]) {
          dbg[0][i] = clipped ? 1.0f : 0.0f;
          dbg[1][i] = no_history ? 1.0f : 0.0f;
          dbg[2][i] = mvx;
          dbg[3][i] = mvy;
        }
      }
    resets += local_resets;
    clips += local_clips;
  });
}

}  // namespace

Expected<TaaConfig> detail::resolve_taa(const TaaParams& p) {
  TaaConfig cfg;
  cfg.alpha = p.alpha;
  cfg.gamma = p.gamma;
  if (!(p.alpha >= 0.0f && p.alpha <= 1.0f)) return Error::usage("--taa-alpha must be in [0, 1]");
  if (!(p.gamma > 0.0f && std::isfinite(p.gamma))) return Error::usage("--taa-gamma must be a finite number > 0");
  if (p.velocity == "nearest")
    cfg.velocity = TaaVelocity::Nearest;
  else if (p.velocity == "centre")
    cfg.velocity = TaaVelocity::Centre;
  else
    return Error::usage("--taa-velocity '" + p.velocity + "' is not one of: nearest, centre");
  if (p.clip == "variance")
    cfg.clip = TaaClip::Variance;
  else if (p.clip == "minmax")
    cfg.clip = TaaClip::MinMax;
  else
    return Error::usage("--taa-clip '" + p.clip + "' is not one of: variance, minmax");
  auto fetch = parse_history_fetch(p.history, "--taa-history");
  if (!fetch) return fetch.error();
  cfg.history = *fetch;
  return cfg;
}

Status detail::check_taa_input(const TaaConfig& cfg, const FilterInput& in) {
  if (cfg.velocity == TaaVelocity::Nearest && in.motion_x && !in.depth)
    return Error::usage("taa: --taa-velocity nearest takes the motion of the closest surface and needs the "
                        "G-buffer's depth; render it (render-gbuffer --outputs gbuffer) or use --taa-velocity centre");
  return Status::ok();
}

TaaFilter::TaaFilter(TaaParams params) : params_(params) {}

std::vector<std::string> TaaFilter::state_channel_names(int channels) {
  return detail::history_channel_names(channels);
}

Status TaaFilter::process(const FilterInput& in, Image& output, FilterStats* stats) {
  if (Status s = validate_filter_input(in); !s) return s;
  const int channels = int(in.channels.size());
  const int w = in.color->width(), h = in.color->height();
  auto cfg = detail::resolve_taa(params_);
  if (!cfg) return cfg.error();
  if (Status s = detail::check_taa_input(*cfg, in); !s) return s;
  const bool same = have_state_ && channels == channels_ && history_.width() == w && history_.height() == h;
  if (!same) {
    channels_ = channels;
    detail::allocate_history(history_, next_, channels, w, h);
  }
  const std::size_t non_finite = detail::prepare_frame(in, channels == 3, ycgco_, valid_);
  float* out[3] = {};
  detail::prepare_output(in, output, out);
  float* dbg[4] = {};
  if (in.debug) {
    dbg[0] = output.add_channel("debug.clip");
    dbg[1] = output.add_channel("debug.noHistory");
    dbg[2] = output.add_channel("debug.velocity.X");
    dbg[3] = output.add_channel("debug.velocity.Y");
  }
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
    run_taa<3>(in, params_, *cfg, same, hist, next, box, valid_.data(), out, dbg, resets, clips);
  else
    run_taa<1>(in, params_, *cfg, same, hist, next, box, valid_.data(), out, dbg, resets, clips);
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

// --- Registry entry (temporal/phlm/filters.h) ------------------------------------------------------------------

namespace {

// taa's parameters on the command line: the fields of TaaParams (taa.h).
struct TaaOptions : TaaParams {
  ParamList params() {
    return {
        Param::real("--taa-alpha", "weight of the current frame (chosen on the tuning set, docs/filter-phlm.md)",
                    &alpha, 0.0, 1.0),
        Param::choice("--taa-velocity",
                      "motion of the closest surface of the 3x3 neighbourhood (nearest, UE4) or of the pixel",
                      &velocity, {"nearest", "centre"}),
        Param::choice("--taa-clip",
                      "history clipping in YCoCg to mu +- gamma sigma (variance, Salvi 2016) or to the 3x3 min/max "
                      "box (minmax, Karis 2014)",
                      &clip, {"variance", "minmax"}),
        Param::positive("--taa-gamma", "gamma of variance clipping (Salvi 2016: 1)", &gamma, 0.0, 8.0),
        Param::choice("--taa-history", "history fetch (Karis 2014: catmull-rom)", &history,
                      {"catmull-rom", "bilinear", "nearest"}),
    };
  }
};

}  // namespace

const MethodEntry& taa_method() {
  static const MethodEntry entry{
      .info = {.name = "taa",
               .summary = "engine-strength TAA: Karis 2014 with nearest-depth velocity, Catmull-Rom history, variance "
                          "clipping (Salvi 2016)",
               .has_state = true},
      .make_options = OptionsOf<TaaOptions>::make,
      .layers = [](const FilterOptions&) { return std::vector<LayerNeed>{{"motion"}, {"depth", false}}; },
      .implementations = {{kCpuDevice, [](const FilterOptions& o) -> std::unique_ptr<FrameFilter> {
                             return std::make_unique<TaaFilter>(method_options<TaaOptions>(o.per_method, "taa"));
                           }},
                          {kGpuDevice,
                           [](std::shared_ptr<gpu::Context> c,
                              const FilterOptions& o) -> Expected<std::unique_ptr<FrameFilter>> {
                             return make_taa_filter_gpu(std::move(c), method_options<TaaOptions>(o.per_method, "taa"));
                           }}},
  };
  return entry;
}

}  // namespace temporal::phlm
