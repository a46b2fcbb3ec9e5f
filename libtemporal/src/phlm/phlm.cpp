// Pixel History Linear Models, seed 003 sections 4-6 and Algorithm 1. The terms the paper leaves loose and
// how they are read here are listed in docs/filter-phlm.md ("Reading the paper").
#include "temporal/phlm/phlm.h"

#include "filter_common.h"
#include "temporal/phlm/filters.h"
#include "temporal/phlm/gpu_filters.h"
#include "temporal/core/color.h"
#include "temporal/core/minmax.h"
#include "temporal/core/parallel.h"
#include "temporal/core/reproject.h"
#include "temporal/phlm/rls.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <vector>

namespace temporal::phlm {
namespace {

template <int C>
constexpr int kN = C + 1;

// Luminance used by the feature heuristic and the model scale: the Y of YCgCo (section 5.1: "we transform
// RGB samples into luminance values, using the YCgCo colorspace"); a one-channel payload is its own luma.
template <int C>
inline float luma(const float* v) {
  if constexpr (C == 3)
    return 0.25f * v[0] + 0.5f * v[1] + 0.25f * v[2];
  else
    return v[0];
}

// The box test of Algorithm 1 runs in YCgCo for colour (section 5.2 names RGB or YCgCo; YCgCo gives a tighter
// box around chroma, as in Karis 2014) and on the value itself for one channel: to_ycgco_box (core/color.h).

// Scale of a model reset to colour c: the regression runs on y / s and z / s so that the predictor
// x = [1, z / s] stays of order one. s = 1 for values up to 1 (the paper's setting, unchanged); HDR values
// (1e4) would otherwise make P ill-conditioned beyond float precision. See docs, "HDR scaling".
template <int C>
inline float model_scale(const float* c) {
  return fast_max(1.0f, std::fabs(luma<C>(c)));
}

// One pixel's model record, interleaved: beta (C x N), D (N), U (N (N - 1) / 2), feature (C), scale (1), in the
// order of PhlmFilter::state_channel_names. The models are fetched at p + motion, 2 x 2 records at a time:
// interleaved records make that two short contiguous reads instead of one scattered read per plane (26 planes
// x 2 rows of streams defeat the hardware prefetchers: one 1080p frame with fractional motion took 476 ms on one
// core with planes, 143 ms with records; docs/filter-phlm.md, "Performance").
template <int C>
struct Layout {
  static constexpr int N = kN<C>;
  static constexpr int kOff = rls::kOffDiagonal<N>;
  static constexpr int kBeta = 0;
  static constexpr int kD = C * N;
  static constexpr int kU = kD + N;
  static constexpr int kFeature = kU + kOff;
  static constexpr int kScale = kFeature + C;
  static constexpr int kSize = kScale + 1;
  static_assert(kSize == phlm_state_floats(C));
};

// The resolved ablation switches of PhlmParams.
struct Variant {
  bool feature = true, box_test = true, alpha_eq1 = false, phi_linear = false;
  HistoryFetch fetch = HistoryFetch::Bilinear;
};

Expected<Variant> resolve_variant(const PhlmParams& p) {
  Variant v;
  v.feature = !p.no_feature;
  v.box_test = !p.no_box_test;
  if (p.alpha_reading == "eq1")
    v.alpha_eq1 = true;
  else if (p.alpha_reading != "ue4")
    return Error::usage("--feature-alpha '" + p.alpha_reading + "' is not one of: ue4, eq1");
  if (p.feature_phi == "linear")
    v.phi_linear = true;
  else if (p.feature_phi != "paper")
    return Error::usage("--feature-phi '" + p.feature_phi + "' is not one of: paper, linear");
  auto fetch = parse_history_fetch(p.model_fetch, "--model-fetch");
  if (!fetch) return fetch.error();
  v.fetch = *fetch;
  return v;
}

struct FrameScratch {
  const float* y[3];       // input planes
  const float* box[3];     // input in box space (YCgCo or the value)
  const std::uint8_t* valid;
};

// The 3x3 neighbourhood of every pixel of one row (Algorithm 1 line 13, the axis-aligned colour box of section 5.2;
// section 5.1's luma range Delta(Y) is box[0]'s extent): the box min / max in box space and the low-frequency
// colour (a [1 2 1]^2 / 16 binomial filter of the input) that the feature accumulates, with the filter's weight
// sum. Non-finite samples are left out (weight 0, +-inf for the box); edges repeat. Separable: a vertical pass
// into columns padded by one on each side, then a horizontal pass; both are plain loops over x that the compiler
// vectorises, and the per-pixel kernel then reads one value per quantity. One per band of rows (its buffers are
// reused for every row of the band).
template <int C>
class NeighbourhoodRow {
 public:
  explicit NeighbourhoodRow(int w)
      : w_(w), wp_(std::size_t(w) + 2), buf_(wp_ * (3 * C + 1) + std::size_t(w) * (3 * C + 1)) {
    for (int c = 0; c < C; ++c) {
      vmin_[c] = buf_.data() + wp_ * std::size_t(c);
      vmax_[c] = buf_.data() + wp_ * std::size_t(C + c);
      vlow_[c] = buf_.data() + wp_ * std::size_t(2 * C + c);
    }
    vw_ = buf_.data() + wp_ * std::size_t(3 * C);
    float* hbase = buf_.data() + wp_ * std::size_t(3 * C + 1);
    for (int c = 0; c < C; ++c) {
      min[c] = hbase + std::size_t(w) * std::size_t(c);
      max[c] = hbase + std::size_t(w) * std::size_t(C + c);
      low[c] = hbase + std::size_t(w) * std::size_t(2 * C + c);
    }
    weight = hbase + std::size_t(w) * std::size_t(3 * C);
  }

  void compute(const FrameScratch& fs, int yy, int h) {
    vertical(fs, yy, h);
    horizontal();
  }

  // Per pixel x of the row: box min / max per channel, low-frequency colour, filter weight (0: no valid sample).
  float* min[C];
  float* max[C];
  float* low[C];
  float* weight;

 private:
  // Rows yy-1, yy, yy+1 (edges repeat) into the padded columns.
  void vertical(const FrameScratch& fs, int yy, int h) {
    const int w = w_;
    const std::size_t r0 = std::size_t(std::max(yy - 1, 0)) * std::size_t(w);
    const std::size_t r1 = std::size_t(yy) * std::size_t(w);
    const std::size_t r2 = std::size_t(std::min(yy + 1, h - 1)) * std::size_t(w);
    const std::uint8_t* v0 = fs.valid + r0;
    const std::uint8_t* v1 = fs.valid + r1;
    const std::uint8_t* v2 = fs.valid + r2;
    for (int xx = 0; xx < w; ++xx) {
      const bool va = v0[xx] != 0, vb = v1[xx] != 0, vc = v2[xx] != 0;
      vw_[xx + 1] = (va ? 1.0f : 0.0f) + (vb ? 2.0f : 0.0f) + (vc ? 1.0f : 0.0f);
    }
    for (int c = 0; c < C; ++c) {
      const float* b0 = fs.box[c] + r0;
      const float* b1 = fs.box[c] + r1;
      const float* b2 = fs.box[c] + r2;
      const float* y0p = fs.y[c] + r0;
      const float* y1p = fs.y[c] + r1;
      const float* y2p = fs.y[c] + r2;
      float* mn = vmin_[c] + 1;
      float* mx = vmax_[c] + 1;
      float* lo = vlow_[c] + 1;
      for (int xx = 0; xx < w; ++xx) {
        const bool va = v0[xx] != 0, vb = v1[xx] != 0, vc = v2[xx] != 0;
        mn[xx] = fast_min(fast_min(va ? b0[xx] : INFINITY, vb ? b1[xx] : INFINITY), vc ? b2[xx] : INFINITY);
        mx[xx] = fast_max(fast_max(va ? b0[xx] : -INFINITY, vb ? b1[xx] : -INFINITY), vc ? b2[xx] : -INFINITY);
        lo[xx] = (va ? y0p[xx] : 0.0f) + 2.0f * (vb ? y1p[xx] : 0.0f) + (vc ? y2p[xx] : 0.0f);
      }
    }
    // Replicate the edge columns into the padding.
    auto pad = [w](float* row) {
      row[0] = row[1];
      row[w + 1] = row[w];
    };
    pad(vw_);
    for (int c = 0; c < C; ++c) {
      pad(vmin_[c]);
      pad(vmax_[c]);
      pad(vlow_[c]);
    }
  }

  // Columns x-1, x, x+1 of the padded columns.
  void horizontal() {
    const int w = w_;
    for (int xx = 0; xx < w; ++xx) weight[xx] = vw_[xx] + 2.0f * vw_[xx + 1] + vw_[xx + 2];
    for (int c = 0; c < C; ++c) {
      const float* mn = vmin_[c];
      const float* mx = vmax_[c];
      const float* lo = vlow_[c];
      float* omn = min[c];
      float* omx = max[c];
      float* olo = low[c];
      for (int xx = 0; xx < w; ++xx) {
        omn[xx] = fast_min(fast_min(mn[xx], mn[xx + 1]), mn[xx + 2]);
        omx[xx] = fast_max(fast_max(mx[xx], mx[xx + 1]), mx[xx + 2]);
        olo[xx] = weight[xx] > 0.0f ? (lo[xx] + 2.0f * lo[xx + 1] + lo[xx + 2]) / weight[xx] : 0.0f;
      }
    }
  }

  int w_;
  std::size_t wp_;
  std::vector<float> buf_;
  float* vmin_[C];
  float* vmax_[C];
  float* vlow_[C];
  float* vw_;
};

// The per-pixel steps below are forced inline into run_phlm's loop: with -march=native the compiler contracts
// a * b + c into FMAs and packs independent operations into vectors, and what it does depends on what is inlined
// where. Left out of line, these steps changed roundings (2e-6 relative in traceP and the output), and outputs and
// state files would no longer equal those of the fused loop they were split from.

// The previous model record at q = p + motion (Algorithm 1 line 11): bilinearly by default (section 6). Integer
// motion (a static scene, a static camera's still objects) reads the one record directly instead of four with
// weights (1, 0, 0, 0).
template <int C>
[[gnu::always_inline]] inline void fetch_record(const float* prev, float fx, float fy, int w, int h, HistoryFetch fetch,
                                                float* rec) {
  using L = Layout<C>;
  constexpr int N = kN<C>;
  if (fetch == HistoryFetch::Nearest) {
    const float* q = prev + reproject::nearest(fx, fy, w, h) * L::kSize;
    for (int k = 0; k < L::kSize; ++k) rec[k] = q[k];
    return;
  }
  const reproject::Bilinear bl = reproject::bilinear(fx, fy, w, h);
  const float* q00 = prev + bl.i00 * L::kSize;
  if (bl.w00 == 1.0f) {
    for (int k = 0; k < L::kSize; ++k) rec[k] = q00[k];
  } else {
    const float* q10 = prev + bl.i10 * L::kSize;
    const float* q01 = prev + bl.i01 * L::kSize;
    const float* q11 = prev + bl.i11 * L::kSize;
    for (int k = 0; k < L::kSize; ++k) rec[k] = bl.w00 * q00[k] + bl.w10 * q10[k] + bl.w01 * q01[k] + bl.w11 * q11[k];
  }
  if (fetch != HistoryFetch::CatmullRom) return;
  // beta and the feature with the 4x4 Catmull-Rom taps; P's factors and the scale keep the bilinear (convex)
  // combination, which keeps D > 0.
  const reproject::CatmullRom cr = reproject::catmull_rom(fx, fy, w, h);
  float acc[C * N + C] = {};
  for (int j = 0; j < 4; ++j)
    for (int k = 0; k < 4; ++k) {
      const float wt = cr.wy[j] * cr.wx[k];
      const float* q = prev + (cr.row[j] + std::size_t(cr.col[k])) * L::kSize;
      for (int e = 0; e < C * N; ++e) acc[e] += wt * q[L::kBeta + e];
      for (int c = 0; c < C; ++c) acc[C * N + c] += wt * q[L::kFeature + c];
    }
  for (int e = 0; e < C * N; ++e) rec[L::kBeta + e] = acc[e];
  for (int c = 0; c < C; ++c) rec[L::kFeature + c] = acc[C * N + c];
}

// What the per-pixel steps read of the frame: the parameters, the 3x3 neighbourhood of the pixel, its input.
template <int C>
struct PixelInputs {
  float bmin[C], bmax[C], low[C], yc[C];
  bool any_valid = false, centre_valid = false;
  float mvx = 0.0f, mvy = 0.0f;
};

// Temporal feature z (section 5.1): exponential accumulation (eq. 1) of the low-frequency colour with the per-pixel
// weight alpha = phi(v, l) / (l + Delta(Y)), phi = a l^2 + b v l^3 as printed, or with --feature-phi linear
// phi = (a + b v) l (UE4's HistoryFactor = DistToClamp * HistoryAmount). `zh` is the fetched feature (ignored on a
// reset).
// Returns alpha (the debug layer).
template <int C>
[[gnu::always_inline]] inline float update_feature(const PixelInputs<C>& p, const PhlmParams& params,
                                                   const Variant& variant, bool reset, const float* zh_fetched,
                                                   float* z) {
  if (reset) {
    // Section 6: "Our temporal feature z is initialized with the input image, z(0) = y(0)".
    for (int c = 0; c < C; ++c) z[c] = p.centre_valid ? p.yc[c] : p.low[c];
    return 1.0f;
  }
  float zh[C];
  for (int c = 0; c < C; ++c) zh[c] = zh_fetched[c];
  if (!p.any_valid) {
    for (int c = 0; c < C; ++c) z[c] = zh[c];
    return 0.0f;
  }
  // Luminances enter the heuristic relative to k = max(1, Y(low)): values up to 1 (the display-referred range the
  // constants a, b were tuned for) are used as they are, HDR values by their Weber contrast, so that alpha does not
  // saturate to 1 on highlights (docs, "HDR scaling").
  const float k = 1.0f / fast_max(1.0f, std::fabs(luma<C>(p.low)));
  const float lh = luma<C>(zh);
  const float delta = (p.bmax[0] - p.bmin[0]) * k;  // box[0] is the luma (YCgCo Y)
  const float l = fast_min(std::fabs(lh - p.bmin[0]), std::fabs(lh - p.bmax[0])) * k;
  const float v = std::sqrt(p.mvx * p.mvx + p.mvy * p.mvy);
  // Section 5.1 as printed: phi = a l^2 + b v l^3. The linear form (ablation): phi = (a + b v) l, one power of l
  // fewer in each term, so that on a static pixel alpha = a l / (l + Delta) as UE4's BlendFinal.
  const float phi = variant.phi_linear ? (params.feature_a + params.feature_b * v) * l
                                       : params.feature_a * l * l + params.feature_b * v * l * l * l;
  const float den = l + delta;
  const float alpha = den > 0.0f ? fast_min(phi / den, 1.0f) : 0.0f;
  // The accumulated feature is kept inside the current neighbourhood box (as Karis' history), so a disoccluded
  // region cannot keep a stale feature.
  float zb[C];
  to_ycgco_box(zh, zb, C);
  for (int c = 0; c < C; ++c) zb[c] = std::clamp(zb[c], p.bmin[c], p.bmax[c]);
  from_ycgco_box(zb, zh, C);
  // alpha weighs the new low-frequency sample (the reading of Karis / UE4, whose code the constants a, b come from;
  // see docs): z = (1 - alpha) z_prev + alpha low. The eq1 ablation reads it as eq. 1's history weight:
  // z = alpha z_prev + (1 - alpha) low.
  if (variant.alpha_eq1)
    for (int c = 0; c < C; ++c) z[c] = p.low[c] + alpha * (zh[c] - p.low[c]);
  else
    for (int c = 0; c < C; ++c) z[c] = zh[c] + alpha * (p.low[c] - zh[c]);
  return alpha;
}

// Algorithm 1 line 9 / section 6 "Initialization": the model reset to colour c0 (scale s, P = p_init I).
template <int C>
[[gnu::always_inline]] inline void reset_model(rls::Model<kN<C>, C>& m, float& s, const float* c0, float p_init) {
  s = model_scale<C>(c0);
  float v0[C];
  for (int c = 0; c < C; ++c) v0[c] = c0[c] / s;
  rls::reset(m, v0, p_init);
}

// eq. 3, x = [1, z / s]; without the feature x = [1, 0, ..]: an intercept-only RLS (Bierman's update then leaves the
// slopes at 0 and U = I, so it is exactly the scalar recursion of a weighted running mean).
template <int C>
[[gnu::always_inline]] inline void predictor(const Variant& variant, const float* z, float s, float* x) {
  x[0] = 1.0f;
  for (int c = 0; c < C; ++c) x[c + 1] = variant.feature ? z[c] / s : 0.0f;
}

// Algorithm 1 lines 12-19: the initial prediction f of the model, the box test against the neighbourhood and, when
// f is outside, the ray-box clip from f towards the input y and the model reset to the clipped colour (line 18).
// Returns true when the model was reset.
template <int C>
[[gnu::always_inline]] inline bool box_test(const PixelInputs<C>& p, const Variant& variant, const float* z,
                                            float p_init, rls::Model<kN<C>, C>& m, float& s, float* x) {
  float f[C], fb[C], yb[C];
  for (int c = 0; c < C; ++c) f[c] = s * rls::predict(m, c, x);
  to_ycgco_box(f, fb, C);
  to_ycgco_box(p.yc, yb, C);
  bool inside = true;
  for (int c = 0; c < C; ++c) inside = inside && fb[c] >= p.bmin[c] && fb[c] <= p.bmax[c];
  if (inside || !variant.box_test) return false;
  bool finite = true;
  for (int c = 0; c < C; ++c) finite = finite && std::isfinite(fb[c]);
  float t_hit = 1.0f;  // a non-finite prediction is replaced by the input itself
  if (finite) {
    // Slab intersection of the ray f + t (y - f) with the box; y is inside the box (it is one of its samples), so
    // the entry point is at t in [0, 1].
    float t_near = 0.0f;
    for (int c = 0; c < C; ++c) {
      const float dir = yb[c] - fb[c];
      if (dir == 0.0f) continue;
      const float t0 = (p.bmin[c] - fb[c]) / dir, t1 = (p.bmax[c] - fb[c]) / dir;
      t_near = fast_max(t_near, fast_min(t0, t1));
    }
    t_hit = fast_min(t_near, 1.0f);
  }
  for (int c = 0; c < C; ++c) fb[c] = finite ? fb[c] + t_hit * (yb[c] - fb[c]) : yb[c];
  from_ycgco_box(fb, f, C);
  reset_model<C>(m, s, f, p_init);  // line 18: Reset(beta, P) <- f
  predictor<C>(variant, z, s, x);
  return true;
}

// Line 22 / eq. 8: the output is the updated model's prediction. Where this frame has no sample the carried model
// was not box-tested (Algorithm 1 tests against y, which is missing): its prediction is clamped to the box of the
// valid neighbours, so a stale or extrapolating model cannot leave the local range (the model itself is kept
// unchanged for the next frame).
template <int C>
[[gnu::always_inline]] inline void predict_output(const PixelInputs<C>& p, const rls::Model<kN<C>, C>& m, float s,
                                                  const float* x, float* f) {
  for (int c = 0; c < C; ++c) f[c] = s * rls::predict(m, c, x);
  if (!p.centre_valid && p.any_valid) {
    float fb[C];
    to_ycgco_box(f, fb, C);
    for (int c = 0; c < C; ++c) fb[c] = std::isfinite(fb[c]) ? std::clamp(fb[c], p.bmin[c], p.bmax[c]) : p.bmin[c];
    from_ycgco_box(fb, f, C);
  }
}

// The model record of this frame (the next frame fetches it).
template <int C>
[[gnu::always_inline]] inline void store_record(const rls::Model<kN<C>, C>& m, const float* z, float s, float* r) {
  using L = Layout<C>;
  constexpr int N = kN<C>;
  for (int c = 0; c < C; ++c)
    for (int k = 0; k < N; ++k) r[L::kBeta + std::size_t(c * N + k)] = m.beta[c][k];
  for (int k = 0; k < L::kOff; ++k) r[L::kU + std::size_t(k)] = m.u[k];
  for (int k = 0; k < N; ++k) r[L::kD + std::size_t(k)] = m.d[k];
  for (int c = 0; c < C; ++c) r[L::kFeature + std::size_t(c)] = z[c];
  r[L::kScale] = s;
}

// Counts of one band of rows.
struct BandCounts {
  std::size_t resets = 0, clamps = 0;
  float max_trace = 0.0f;
};

// Algorithm 1 for pixel (xx, yy), whose neighbourhood and input are `p`: reprojection (line 6), fetch or reset of the
// model (lines 7-11), feature (section 5.1), box test (lines 12-19), RLS update (lines 20-21, eq. 5-7), output
// (line 22, eq. 8), and the record for the next frame.
template <int C>
[[gnu::always_inline]] inline void phlm_pixel(const FilterInput& in, const PhlmParams& params, const Variant& variant,
                                              bool have_prev, const float* prev, float* next, const PixelInputs<C>& p,
                                              int xx, int yy, std::size_t i, float* const out[C],
                                              float* const dbg[3 + C], BandCounts& counts) {
  using L = Layout<C>;
  constexpr int N = kN<C>;
  const int w = in.color->width(), h = in.color->height();
  const float p0 = params.p_init;
  // Reprojection q = pi(v) = p + motion (Algorithm 1 line 6); lines 7-9: no model off screen or after a reset.
  const float fx = float(xx) + p.mvx, fy = float(yy) + p.mvy;
  const bool reset = in.reset || !have_prev || !reproject::on_screen(fx, fy, w, h);
  float rec[L::kSize];
  if (!reset) fetch_record<C>(prev, fx, fy, w, h, variant.fetch, rec);
  float z[C];
  const float alpha = update_feature<C>(p, params, variant, reset, rec + L::kFeature, z);

  // Model fetch (line 11) or reset (line 9, section 6 "Initialization").
  rls::Model<N, C> m;
  float s;
  float flag = 0.0f;
  if (reset) {
    reset_model<C>(m, s, p.centre_valid ? p.yc : z, p0);
    flag = 1.0f;
    ++counts.resets;
  } else {
    for (int c = 0; c < C; ++c)
      for (int k = 0; k < N; ++k) m.beta[c][k] = rec[L::kBeta + c * N + k];
    for (int k = 0; k < L::kOff; ++k) m.u[k] = rec[L::kU + k];
    for (int k = 0; k < N; ++k) m.d[k] = rec[L::kD + k];
    s = rec[L::kScale];
  }
  float x[N];
  predictor<C>(variant, z, s, x);

  float trace_p = 0.0f;
  if (p.centre_valid) {
    if (box_test<C>(p, variant, z, p0, m, s, x)) {
      flag = 2.0f;
      ++counts.clamps;
    }
    // Lines 20-21: a-priori error and RLS update (eq. 5-7).
    float yn[C];
    for (int c = 0; c < C; ++c) yn[c] = p.yc[c] / s;
    trace_p = rls::update(m, x, yn, params.lambda, p0, params.trace_factor * float(N) * p0);
  } else {
    // No valid sample at this pixel this frame: the model is carried over unchanged (conventions: non-finite input
    // never enters a history).
    trace_p = rls::trace<N>(m.u, m.d);
  }
  counts.max_trace = fast_max(counts.max_trace, trace_p);

  float f[C];
  predict_output<C>(p, m, s, x, f);
  for (int c = 0; c < C; ++c) out[c][i] = f[c];
  store_record<C>(m, z, s, next + i * L::kSize);
  if (dbg[0]) {
    for (int c = 0; c < C; ++c) dbg[3 + c][i] = z[c];
    dbg[0][i] = alpha;
    dbg[1][i] = flag;
    dbg[2][i] = trace_p;
  }
}

// One frame of PHLM: per band of rows, the neighbourhood of each row, then Algorithm 1 per pixel.
template <int C>
void run_phlm(const FilterInput& in, const PhlmParams& params, const Variant& variant, bool have_prev,
              const float* prev, float* next,
              const FrameScratch& fs, float* const out[C], float* const dbg[3 + C],
              std::atomic<std::size_t>& resets, std::atomic<std::size_t>& clamps, float& max_trace) {
  const int w = in.color->width(), h = in.color->height();
  std::atomic<std::uint32_t> max_trace_bits{0};  // positive floats order like their bit patterns

  parallel_rows(h, [&](int y0, int y1) {
    BandCounts counts;
    NeighbourhoodRow<C> nb(w);
    for (int yy = y0; yy < y1; ++yy) {
      nb.compute(fs, yy, h);
      for (int xx = 0; xx < w; ++xx) {
        const std::size_t i = std::size_t(yy) * std::size_t(w) + std::size_t(xx);
        PixelInputs<C> p;
        for (int c = 0; c < C; ++c) {
          p.bmin[c] = nb.min[c][xx];
          p.bmax[c] = nb.max[c][xx];
          p.low[c] = nb.low[c][xx];
          p.yc[c] = fs.y[c][i];
        }
        p.any_valid = nb.weight[xx] > 0.0f;
        p.centre_valid = fs.valid[i] != 0;
        p.mvx = in.motion_x ? in.motion_x[i] : 0.0f;
        p.mvy = in.motion_y ? in.motion_y[i] : 0.0f;
        phlm_pixel<C>(in, params, variant, have_prev, prev, next, p, xx, yy, i, out, dbg, counts);
      }
    }
    resets += counts.resets;
    clamps += counts.clamps;
    std::uint32_t bits;
    std::memcpy(&bits, &counts.max_trace, sizeof bits);
    std::uint32_t cur = max_trace_bits.load();
    while (bits > cur && !max_trace_bits.compare_exchange_weak(cur, bits)) {
    }
  });
  const std::uint32_t bits = max_trace_bits.load();
  std::memcpy(&max_trace, &bits, sizeof max_trace);
}

}  // namespace

PhlmFilter::PhlmFilter(PhlmParams params) : params_(params) {}

std::vector<std::string> PhlmFilter::state_channel_names(int channels) {
  const int n = channels + 1;
  std::vector<std::string> names;
  for (int c = 0; c < channels; ++c)
    for (int k = 0; k < n; ++k) names.push_back("beta." + std::string(detail::channel_suffix(channels, c)) + std::to_string(k));
  for (int k = 0; k < n; ++k) names.push_back("P.D" + std::to_string(k));
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) names.push_back("P.U" + std::to_string(i) + std::to_string(j));
  for (int c = 0; c < channels; ++c) names.push_back("feature." + std::string(detail::channel_suffix(channels, c)));
  names.push_back("scale.s");
  return names;
}

Status PhlmFilter::process(const FilterInput& in, Image& output, FilterStats* stats) {
  if (Status s = validate_filter_input(in); !s) return s;
  const auto variant = resolve_variant(params_);
  if (!variant) return variant.error();
  const int channels = int(in.channels.size());
  const int w = in.color->width(), h = in.color->height();
  const bool same_shape = have_state_ && channels == channels_ && width_ == w && height_ == h;
  if (!same_shape) {
    channels_ = channels;
    width_ = w;
    height_ = h;
    const std::size_t n = std::size_t(w) * std::size_t(h) * std::size_t(phlm_state_floats(channels));
    state_.assign(n, 0.0f);
    next_.assign(n, 0.0f);
  }
  const bool have_prev = same_shape;

  FrameScratch fs{};
  const std::size_t non_finite = detail::prepare_frame(in, channels == 3, ycgco_, valid_);
  for (int c = 0; c < channels; ++c) {
    fs.y[c] = in.color->plane(in.channels[std::size_t(c)]);
    fs.box[c] = channels == 3 ? ycgco_[std::size_t(c)].data() : fs.y[c];
  }
  fs.valid = valid_.data();

  float* out[3] = {};
  detail::prepare_output(in, output, out);
  float* dbg[6] = {};
  if (in.debug) {
    dbg[0] = output.add_channel("debug.alpha");
    dbg[1] = output.add_channel("debug.reset");
    dbg[2] = output.add_channel("debug.traceP");
    for (int c = 0; c < channels; ++c)
      dbg[3 + c] = output.add_channel(channels == 3 ? "debug.feature" + std::string(detail::channel_suffix(3, c))
                                                    : std::string("debug.feature"));
  }

  std::atomic<std::size_t> resets{0}, clamps{0};
  float max_trace = 0.0f;
  if (channels == 3) {
    run_phlm<3>(in, params_, *variant, have_prev, state_.data(), next_.data(), fs, out, dbg, resets, clamps, max_trace);
  } else {
    run_phlm<1>(in, params_, *variant, have_prev, state_.data(), next_.data(), fs, out, dbg, resets, clamps, max_trace);
  }
  std::swap(state_, next_);
  have_state_ = true;
  if (stats) {
    stats->non_finite = non_finite;
    stats->history_resets = resets.load();
    stats->clamped = clamps.load();
    stats->max_trace_p = max_trace;
  }
  return Status::ok();
}

Image PhlmFilter::state() const {
  if (!have_state_) return Image();
  Image img(width_, height_);
  const auto names = state_channel_names(channels_);
  std::vector<float*> planes;
  for (const auto& n : names) planes.push_back(img.add_channel(n));
  const std::size_t size = names.size();
  parallel_chunks(img.pixel_count(), [&](std::size_t b0, std::size_t b1) {
    for (std::size_t i = b0; i < b1; ++i)
      for (std::size_t k = 0; k < size; ++k) planes[k][i] = state_[i * size + k];
  });
  return img;
}

Image PhlmFilter::state_with_covariance() const {
  Image out = state();
  if (!have_state_) return out;
  const int n = channels_ + 1;
  const auto names = state_channel_names(channels_);
  const int off = n * (n - 1) / 2;
  const std::size_t d_first = std::size_t(channels_ * n);
  std::vector<const float*> d(static_cast<std::size_t>(n));
  std::vector<const float*> u(static_cast<std::size_t>(std::max(off, 1)));
  for (int k = 0; k < n; ++k) d[std::size_t(k)] = out.plane(names[d_first + std::size_t(k)]);
  for (int k = 0; k < off; ++k) u[std::size_t(k)] = out.plane(names[d_first + std::size_t(n + k)]);
  std::vector<float*> p;
  for (int i = 0; i < n; ++i)
    for (int j = i; j < n; ++j) p.push_back(out.add_channel("Pmat.P" + std::to_string(i) + std::to_string(j)));
  for (std::size_t i = 0; i < out.pixel_count(); ++i) {
    float uu[6] = {}, dd[4] = {}, pp[10] = {};
    for (int k = 0; k < n; ++k) dd[k] = d[std::size_t(k)][i];
    for (int k = 0; k < off; ++k) uu[k] = u[std::size_t(k)][i];
    if (n == 4)
      rls::covariance<4>(uu, dd, pp);
    else
      rls::covariance<2>(uu, dd, pp);
    for (std::size_t k = 0; k < p.size(); ++k) p[k][i] = pp[k];
  }
  return out;
}

Status PhlmFilter::set_state(const Image& state, int channels) {
  if (channels != 1 && channels != 3)
    return Error::usage("phlm state: the filtered layer must have 1 or 3 channels, not " + std::to_string(channels));
  const auto names = state_channel_names(channels);
  std::vector<const float*> planes;
  for (const auto& name : names) {
    const float* src = state.plane(name);
    if (!src)
      return Error::input({}, "state has no channel '" + name + "': write it with `filter-phlm --method phlm " +
                                  "--state-out` on the same --layer");
    if (count_non_finite({src, state.pixel_count()}) != 0)
      return Error::input({}, "state channel '" + name + "' holds NaN or Inf values; it cannot be resumed");
    // P = U D U^T must stay positive definite (D > 0) and the model scale s positive (model_scale gives s >= 1,
    // and bilinear fetches of it stay within rounding of that); anything else is not a state this filter wrote,
    // and would turn the next frame's update into NaN.
    const bool is_d = name.rfind("P.D", 0) == 0, is_scale = name == "scale.s";
    if (is_d || is_scale) {
      for (std::size_t i = 0; i < state.pixel_count(); ++i)
        if (!(src[i] > 0.0f))
          return Error::input({}, "state channel '" + name + "' holds " + std::to_string(src[i]) + " at pixel (" +
                                      std::to_string(i % std::size_t(state.width())) + ", " +
                                      std::to_string(i / std::size_t(state.width())) + "): " +
                                      (is_d ? "P must be positive definite" : "the model scale must be positive") +
                                      "; this is not a state written by filter-phlm --state-out");
    }
    planes.push_back(src);
  }
  channels_ = channels;
  width_ = state.width();
  height_ = state.height();
  const std::size_t size = names.size();
  state_.assign(state.pixel_count() * size, 0.0f);
  next_.assign(state.pixel_count() * size, 0.0f);
  for (std::size_t i = 0; i < state.pixel_count(); ++i)
    for (std::size_t k = 0; k < size; ++k) state_[i * size + k] = planes[k][i];
  have_state_ = true;
  return Status::ok();
}

std::string PhlmFilter::stats_text(const FilterStats& stats) const {
  return ", max trace(P) " + std::to_string(stats.max_trace_p);
}

// --- Registry entry (temporal/phlm/filters.h) ------------------------------------------------------------------

namespace {

// phlm's parameters on the command line: the fields of PhlmParams (phlm.h).
struct PhlmOptions : PhlmParams {
  ParamList params() {
    return {
        Param::real("--lambda", "RLS forgetting factor (seed 003 eq. 6-7)", &lambda, 0.5, 1.0),
        // Finite ranges (issue 26): trace_max = trace_factor * N * p_init and the gain P x / (lambda + x^T P x) of
        // eq. 6 stay finite and nonzero in float.
        Param::real("--p-init", "P = p_init * I at reset (seed 003 section 6)", &p_init, 1e-6, 1e6),
        Param::real("--feature-a", "a of phi(v,l) = a l^2 + b v l^3 (section 5.1)", &feature_a, -1e6, 1e6),
        Param::real("--feature-b", "b of phi(v,l)", &feature_b, -1e6, 1e6),
        Param::real("--trace-factor", "trace(P) <= factor * N * p_init (wind-up guard)", &trace_factor, 1e-3, 1e3),
        Param::flag_on("--no-feature",
                       "ablation: predictor x = [1], an intercept-only RLS (a per-pixel running mean with the same "
                       "resets)",
                       &no_feature),
        Param::flag_on("--no-box-test", "ablation: skip the box test and its resets (Algorithm 1 lines 13-19)",
                       &no_box_test),
        Param::choice("--feature-alpha",
                      "reading of the feature's alpha: ue4 = weight of the new sample, eq1 = history weight of eq. 1 "
                      "(ablation)",
                      &alpha_reading, {"ue4", "eq1"}),
        Param::choice("--feature-phi",
                      "phi of the feature's weight alpha = phi / (l + Delta): paper = a l^2 + b v l^3 (section 5.1 "
                      "as printed), linear = (a + b v) l (UE4's HistoryFactor; ablation)",
                      &feature_phi, {"paper", "linear"}),
        Param::choice("--model-fetch", "fetch of the previous models at p + motion (section 6: bilinear)",
                      &model_fetch, {"bilinear", "nearest", "catmull-rom"}),
    };
  }
};

}  // namespace

const MethodEntry& phlm_method() {
  static const MethodEntry entry{
      .info = {.name = "phlm", .summary = "pixel history linear models (seed 003)", .has_state = true},
      .make_options = OptionsOf<PhlmOptions>::make,
      .layers = [](const FilterOptions&) { return std::vector<LayerNeed>{{"motion"}}; },
      .implementations = {{kCpuDevice, [](const FilterOptions& o) -> std::unique_ptr<FrameFilter> {
                             return std::make_unique<PhlmFilter>(method_options<PhlmOptions>(o.per_method, "phlm"));
                           }},
                          {kGpuDevice,
                           [](std::shared_ptr<gpu::Context> c,
                              const FilterOptions& o) -> Expected<std::unique_ptr<FrameFilter>> {
                             return make_phlm_filter_gpu(std::move(c), method_options<PhlmOptions>(o.per_method, "phlm"));
                           }}},
  };
  return entry;
}

}  // namespace temporal::phlm
