// `taau`: an engine-class temporal upscaler, the modern baseline of issue 15, written from the public descriptions
// of AMD FidelityFX Super Resolution 2 (FSR 2: the GDC 2022 talk "FidelityFX Super Resolution 2.0" and its MIT
// shader source, ffx_fsr2_upsample.h / ffx_fsr2_accumulate.h / ffx_fsr2_lock.h, versions 2.0-2.2) and of Unreal
// Engine 4's TAAU (Karis 2014, "High Quality Temporal Supersampling": YCoCg neighbourhood clamp of the history).
// Not a port: one CPU pass per frame over full-resolution rows, with the choices below (docs/upsample-st.md, "taau",
// lists each with its source).
//
// Per full-resolution pixel p (this frame's jittered low-resolution samples sit at full-resolution pixel centres,
// docs/conventions.md, "Jitter"):
//  1. History (FSR 2 "ReprojectHistoryColor"): the previous output, its accumulation weight and its lock at
//     p + motion through the shared reprojection module (temporal/core/reproject.h): off-screen rule, bilinear taps,
//     per-tap depth (and id) disocclusion test, FSR 2's depth clip. A miss makes p a "new sample". The colour is
//     re-read with the module's Catmull-Rom fetch (UE4) where all four bilinear taps were kept.
//  2. Reconstruction of this frame's samples (FSR 2 ComputeUpsampledColorAndWeight): the 3x3 low-resolution
//     samples around the nearest one, each weighted by Lanczos-2 (FSR 2's polynomial approximation
//     Lanczos2ApproxSq) of its offset from p in low-resolution pixels times the kernel bias (min(1.99, k) with
//     history, 1 for a new sample: a wider, smoother kernel where there is nothing to accumulate); the sum of
//     weights / 12 (fUpsampleLanczosWeightScale) is the new sample's accumulation weight; the result is clamped to
//     the samples' range (FSR 2 "Deringing", the negative lobes must not ring).
//  3. Rectification (FSR 2 RectifyHistory; Karis 2014): in YCoCg, a box of the 3x3 samples, mean +- s sigma with
//     weights exp(c |offset|^2) intersected with their min/max; a history outside it is moved towards it (fully
//     when far outside) and its accumulation weight falls towards 0.1 alike, unless a lock protects it.
//  4. Accumulation (FSR 2.0 Accumulate): per-pixel weight a := min(a, max) + w_new, output = history + (new -
//     history) w_new / a; max = 1 (fMaxAccumulationLanczosWeight), 3/12 while the pixel moves (accumulationMaxOnMotion).
//  5. Locks (FSR 2 ffx_fsr2_lock.h, ComputeThinFeatureConfidence): a low-resolution sample that is a luminance
//     ridge no 2x2 quad of similar neighbours explains (a thin feature: wire, edge highlight) locks its pixel; a lock
//     re-detected while alive gets lifetime 2, and a lifetime above 1 keeps the history from being clamped. The
//     lifetime decreases with the accumulated weight (one jitter cycle of average weight takes 1) and the lock dies on
//     a disocclusion or when the luminance under it changes by more than 10 %.
// Colour channels are rectified in YCoCg in threes (R, G, B of each payload layer; any channels left over one by one).
#include "taau.h"
#include "gpu_methods.h"

#include "temporal/core/color.h"
#include "temporal/core/parallel.h"

#include <atomic>
#include <cmath>
#include <limits>

namespace temporal::upsample {

const TaauOptions& taau_options(const Options& o) { return method_options<TaauOptions>(o.per_method, "taau"); }

namespace {

// FSR 2's Lanczos2ApproxSq (from FSR 1's EASU): Lanczos-2 without sin or sqrt, of the squared distance x2:
// (25/16 (2/5 x2 - 1)^2 - (25/16 - 1)) (1/4 x2 - 1)^2 for x2 < 4, else 0. 1 at 0, 0 at 1, a negative lobe on (1, 2).
inline float lanczos2_approx_sq(float x2) {
  x2 = std::min(x2, 4.0f);
  const float a = 0.4f * x2 - 1.0f, b = 0.25f * x2 - 1.0f;
  return (25.0f / 16.0f * a * a - (25.0f / 16.0f - 1.0f)) * b * b;
}

// The payload is filtered in the box space of core/color.h (to_ycgco_box): R, G, B triples as YCoCg (Malvar &
// Sullivan 2003; Karis 2014 and FSR 2 clamp there), other channels as they are. Linear, so blends are the same in
// either space.

// FSR 2 ComputeThinFeatureConfidence on the low-resolution luminance: sample (x, y) is a thin feature when its
// luminance is outside the range of its dissimilar 3x3 neighbours (a ridge) and no 2x2 quad containing it is all
// similar (ratio below 1.05). Edges repeat (FSR 2's ClampLoad).
bool thin_feature(const std::vector<float>& luma, int lw, int lh, int x, int y) {
  const float nucleus = luma[std::size_t(y) * lw + x];
  float dmin = std::numeric_limits<float>::max(), dmax = 0.0f;
  unsigned mask = 1u << 4;
  int idx = 0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx, ++idx) {
      if (dx == 0 && dy == 0) continue;
      const int sx = std::clamp(x + dx, 0, lw - 1), sy = std::clamp(y + dy, 0, lh - 1);
      const float s = luma[std::size_t(sy) * lw + sx];
      const float diff = std::max(s, nucleus) / std::min(s, nucleus);
      if (diff > 0 && diff < kSimilarLuma) {
        mask |= 1u << idx;
      } else {
        dmin = std::min(dmin, s);
        dmax = std::max(dmax, s);
      }
    }
  if (!(nucleus > dmax || nucleus < dmin)) return false;
  static constexpr unsigned kQuads[4] = {(1u << 0) | (1u << 1) | (1u << 3) | (1u << 4),
                                         (1u << 1) | (1u << 2) | (1u << 4) | (1u << 5),
                                         (1u << 3) | (1u << 4) | (1u << 6) | (1u << 7),
                                         (1u << 4) | (1u << 5) | (1u << 7) | (1u << 8)};
  for (unsigned q : kQuads)
    if ((mask & q) == q) return false;
  return true;
}

class TaauState : public MethodState {
 public:
  TaauState(const Options&, const Geometry& g) : out_(g), g_(g) {
    const std::size_t N = std::size_t(g.W) * g.H;
    for (int i = 0; i < 2; ++i) {
      acc_[i].assign(N, 0.0f);
      lock_[i].assign(N, 0.0f);
      lock_luma_[i].assign(N, 0.0f);
    }
  }

  Image& run(const FrameContext& f, bool history, FrameStats& stats) override;
  void find_thin_features(const FrameContext& f, const TaauOptions& to);
  void fetch_history_row(const FrameContext& f, bool history, int prv, const std::vector<const float*>& prev_planes,
                         int Y, HistoryRow& hist, std::vector<float>& fetched) const;
  void update_lock(const FrameContext& f, const TaauOptions& to, bool hit, const float* result, int X, int Y,
                   float w_new, float lifetime_per_weight, float& lock, float& lock_luma) const;

  void save(Image& state) const override {
    const int c = out_.index();
    for (const auto& ch : g_.channels) put_plane(state, "history." + ch, out_.current().plane(ch), g_.W, g_.H);
    put_plane(state, "history.weight", acc_[c].data(), g_.W, g_.H);
    put_plane(state, "lock.lifetime", lock_[c].data(), g_.W, g_.H);
    put_plane(state, "lock.luma", lock_luma_[c].data(), g_.W, g_.H);
    put_previous(state, prev_, g_.W, g_.H);
  }
  Status load(const Image& state) override {
    Image& img = out_.next();
    const int c = out_.index();
    for (const auto& ch : g_.channels)
      if (Status s = get_plane(state, "history." + ch, img.plane(ch), g_.W, g_.H); !s) return s;
    if (Status s = get_plane(state, "history.weight", acc_[c].data(), g_.W, g_.H); !s) return s;
    if (Status s = get_plane(state, "lock.lifetime", lock_[c].data(), g_.W, g_.H); !s) return s;
    if (Status s = get_plane(state, "lock.luma", lock_luma_[c].data(), g_.W, g_.H); !s) return s;
    return get_previous(state, prev_, g_.W, g_.H);
  }

 private:
  OutputPair out_;
  Geometry g_;
  PreviousGeometry prev_;
  std::vector<float> acc_[2], lock_[2], lock_luma_[2];  // ping-pong like the output pair
  std::vector<float> low_luma_;
  std::vector<char> thin_;
};

// Step 2 for one output pixel (X, Y): the 3x3 low-resolution samples around the nearest one (xn, yn), in filter
// space (to_ycgco_box): their Lanczos-2 sum (FSR 2's approximation, kernel `bias`), and the box of step 3: the weighted mean
// (weights exp(curve d^2), FSR 2's fRectificationCurveBias), spread, min and max.
struct SampleBox {
  float sum[16] = {}, bsum[16] = {}, bsq[16] = {}, lo[16] = {}, hi[16] = {};
  float wsum = 0.0f, bw = 0.0f;
  int samples = 0;
};

SampleBox gather_samples(const FrameContext& f, int xn, int yn, int X, int Y, float bias, float curve) {
  const int C = f.C, lw = f.lw, lh = f.lh, k = f.grid.k, sx = f.grid.sx, sy = f.grid.sy;
  const float inv_k = 1.0f / float(k);
  SampleBox b;
  float* sum = b.sum;
  float* bsum = b.bsum;
  float* bsq = b.bsq;
  float* lo = b.lo;
  float* hi = b.hi;
  float& wsum = b.wsum;
  float& bw = b.bw;
  int& samples = b.samples;
  float vals[9][16], wbs[9];  // the samples (filter space) and box weights, for the box's second pass
  for (int dy = -1; dy <= 1; ++dy) {
    const int ly = yn + dy;
    if (ly < 0 || ly >= lh) continue;  // FSR 2's fOnScreenFactor
    for (int dx = -1; dx <= 1; ++dx) {
      const int lx = xn + dx;
      if (lx < 0 || lx >= lw) continue;
      const std::size_t s = std::size_t(ly) * lw + lx;
      if (!(f.lvalid[s] > 0)) continue;  // a non-finite sample or geometry does not exist
      const float ox = float(k * lx + sx - X) * inv_k, oy = float(k * ly + sy - Y) * inv_k;
      const float d2 = ox * ox + oy * oy;
      const float wl = lanczos2_approx_sq(d2 * bias * bias);
      const float wb = std::exp(curve * d2);
      float* v = vals[samples];
      wbs[samples] = wb;
      for (int c = 0; c < C; ++c) v[c] = f.low[c][s];
      to_ycgco_box(v, v, C);
      for (int c = 0; c < C; ++c) {
        sum[c] += wl * v[c];
        bsum[c] += wb * v[c];
        lo[c] = samples ? std::min(lo[c], v[c]) : v[c];
        hi[c] = samples ? std::max(hi[c], v[c]) : v[c];
      }
      wsum += wl;
      bw += wb;
      ++samples;
    }
  }
  // The box's spread in a second pass about its mean: E[v^2] - mean^2 (FSR 2's form) loses every digit to
  // cancellation on smooth content, and the box edge mean +- 20 sigma would then follow rounding noise.
  for (int j = 0; j < samples; ++j)
    for (int c = 0; c < C; ++c) {
      const float d = vals[j][c] - bsum[c] / bw;
      bsq[c] += wbs[j] * d * d;
    }
  return b;
}

// One pixel's outcome of steps 2-4, in filter space.
struct PixelResult {
  float result[16];
  float w_new = 0.0f;      // this frame's accumulation weight (debug.confidence)
  float alpha = 0.0f;      // this frame's share of the result (1 - debug.wf)
  float rectified = 0.0f;  // how much of the history was cut (debug.gradient)
};

// Steps 3 and 4 for a pixel with history (FSR 2.2 RectifyHistory, FSR 2 Accumulate): the history `hv` (filter
// space) clipped towards the box of `b` as far as it left it, the accumulation weight `acc` cut as much, then the
// blend with this frame's reconstruction `recon` of weight `w_new`. Writes `result`, `alpha` (this frame's share)
// and `acc`; returns how much of the history was cut (0 kept .. 1 cut: debug.gradient).
float rectify_and_accumulate(const TaauOptions& to, const SampleBox& b, int C, float velocity, float scale_influence,
                             float lock, const float* recon, float w_new, float* hv, float& acc, float& alpha,
                             float* result) {
  const float* bsum = b.bsum;
  const float* bsq = b.bsq;
  const float* lo = b.lo;
  const float* hi = b.hi;
  const float bw = b.bw;
  // FSR 2.0 ComputeMaxAccumulationWeight: 1, 3/12 once the pixel moves by 0.1 px.
  const float max_acc = kMaxAccumulation + (to.motion_accumulation - kMaxAccumulation) *
                                               std::min(1.0f, velocity * 10.0f);
  acc = std::min(acc, max_acc);
  // Step 3: rectification (FSR 2.2 RectifyHistory).
  const float s = to.box_scale > 0
                      ? to.box_scale
                      : scale_influence + (1.0f - scale_influence) * std::min(1.0f, velocity / 20.0f);
  // How much of the history survives, per channel: FSR 2.0's HistoryColorWeight |clamped - centre| /
  // |history - centre| (1 inside the box, falling as the history leaves it), plus the lock's
  // contribution (FSR 2 GetLockContributionThisFrame: saturate(saturate(lifetime - 1) * 4)). Continuous
  // in the history, unlike FSR 2.2's any-channel-outside test, so that float roundings cannot flip it.
  const float lock_keep = to.locks ? std::clamp((lock - 1.0f) * 4.0f, 0.0f, 1.0f) : 0.0f;
  float keep_all = 1.0f;
  for (int c = 0; c < C; ++c) {
    const float mean = bsum[c] / bw;
    const float sigma = std::sqrt(bsq[c] / bw);
    const float bmin = std::max(lo[c], mean - s * sigma), bmax = std::min(hi[c], mean + s * sigma);
    const float clamped = std::clamp(hv[c], bmin, bmax);
    // tau: a flat channel (a zero-width box, e.g. Co of a grey surface) must not turn rounding noise in
    // the history into a clamp; deviations below 1e-5 of the payload's scale count as inside.
    const float centre = 0.5f * (bmin + bmax), tau = 1e-5f * (1.0f + std::max(std::abs(lo[c]), std::abs(hi[c])));
    const float ratio = (std::abs(clamped - centre) + tau) / (std::abs(hv[c] - centre) + tau);
    const float keep = std::min(1.0f, ratio + lock_keep);
    hv[c] = clamped + (hv[c] - clamped) * keep;
    keep_all = std::min(keep_all, keep);
  }
  // FSR 2.2: a rectified history's accumulation falls to at most 0.1, as much as the history was cut.
  const float acc_min = std::min(acc, kRectifiedAccumulation);
  acc = acc_min + (acc - acc_min) * keep_all;
  // Step 4 (FSR 2 Accumulate).
  const float a = std::max(kEpsilon, acc + w_new);
  alpha = w_new / a;
  for (int c = 0; c < C; ++c) result[c] = hv[c] + (recon[c] - hv[c]) * alpha;
  acc = std::min(a, max_acc);
  return 1.0f - keep_all;
}

// Step 5 for one pixel (FSR 2 locks): a lock ends when the luminance of this frame's result moved more than
// --lock-luma-change from the one it was made with; a thin-feature sample at this pixel makes (or renews) one; its
// lifetime is spent by the weight accumulated.
void TaauState::update_lock(const FrameContext& f, const TaauOptions& to, bool hit, const float* result, int X,
                            int Y, float w_new, float lifetime_per_weight, float& lock, float& lock_luma) const {
  const int C = f.C, lw = f.lw, lh = f.lh, k = f.grid.k, sx = f.grid.sx, sy = f.grid.sy;
  // Step 5: locks. Luminance of this frame's reconstruction where it has weight (else the result's).
  if (to.locks) {
    if (!hit) lock = 0.0f;
    float yr = 0.0f;
    {
      float rgb[16];
      for (int c = 0; c < C; ++c) rgb[c] = result[c];
      from_ycgco_box(rgb, rgb, C);
      for (int c = 0; c < C; ++c) yr += f.luma[c] * rgb[c];
    }
    if (lock > 0) {
      const float m = std::max(std::abs(yr), std::abs(lock_luma));
      const float change = m > 0 ? std::abs(yr - lock_luma) / m : 0.0f;
      if (change > to.lock_luma_change) lock = 0.0f;
    }
    // A new lock at the pixel of a thin-feature sample (FSR 2 writes it at the sample's display pixel).
    const int dxs = X - sx, dys = Y - sy;
    if (dxs >= 0 && dys >= 0 && dxs % k == 0 && dys % k == 0 && dxs / k < lw && dys / k < lh &&
        thin_[std::size_t(dys / k) * lw + dxs / k]) {
      lock = lock > 0 ? 2.0f : 1.0f;  // FSR 2: a lock found again while alive
      lock_luma = low_luma_[std::size_t(dys / k) * lw + dxs / k];
    }
    lock = std::max(0.0f, lock - w_new * lifetime_per_weight);
  } else {
    lock = 0.0f;
  }
}

// The history of one row (step 1): the reprojection taps of row Y (temporal/core/reproject.h) and, gathered through
// them, the previous output, accumulation weight, lock lifetime and lock luminance: plane q of `fetched` (W values
// each) is payload channel q < C, then C the weight, C + 1 the lifetime, C + 2 the luminance. Without history every
// pixel is a miss.
void TaauState::fetch_history_row(const FrameContext& f, bool history, int prv,
                                  const std::vector<const float*>& prev_planes, int Y, HistoryRow& hist,
                                  std::vector<float>& fetched) const {
  const int C = f.C, W = f.W;
  const int nf = C + 3;  // colour, weight, lock lifetime, lock luminance
  fetched.resize(std::size_t(nf) * W);
  if (!history) {
    hist.resize(W);
    std::fill(hist.hit.begin(), hist.hit.end(), 0.0f);
    return;
  }
  history_row(f, prev_, Y, hist);
  const float* src[16];
  float* dst[16];
  for (int q0 = 0; q0 < nf; q0 += 16) {
    const int n = std::min(16, nf - q0);
    for (int i = 0; i < n; ++i) {
      const int q = q0 + i;
      src[i] = q < C ? prev_planes[q] : q == C ? acc_[prv].data() : q == C + 1 ? lock_[prv].data()
                                                                              : lock_luma_[prv].data();
      dst[i] = fetched.data() + std::size_t(q) * W;
    }
    reproject::gather_row(hist, src, dst, n, W);
  }
}

// Step 1's colour filter: UE4 TAAU's bicubic (Catmull-Rom) history (Karis 2014: the bilinear fetch blurs a little more
// every frame), only where the module's fetch kept the four bilinear taps at their plain weights (no tap of another
// surface, none outside), so the disocclusion test still decides. The module's 4x4 fetch replaces hv (C channels,
// the payload's space) there.
void catmull_rom_history(const FrameContext& f, const HistoryRow& hist, const std::vector<const float*>& prev_planes,
                         int X, int Y, float* hv) {
  const std::size_t i = std::size_t(Y) * f.W + X;
  const float u = float(X) + f.mx[i], v = float(Y) + f.my[i];
  const float ax = u - std::floor(u), ay = v - std::floor(v);
  const float raw[4] = {(1 - ax) * (1 - ay), ax * (1 - ay), (1 - ax) * ay, ax * ay};
  bool full = true;
  for (int j = 0; j < 4; ++j) full = full && std::abs(hist.w[j][X] - raw[j]) <= 1e-5f;
  if (!full) return;
  const reproject::CatmullRom cr = reproject::catmull_rom(u, v, f.W, f.H);
  for (int c = 0; c < f.C; ++c) hv[c] = cr(prev_planes[c]);
}

// Steps 2-4 for one pixel, all values in filter space: this frame's reconstruction from the samples `b` and, with a
// history hit, the rectified history blended with it. Without a sample near p the history is kept as it is (or 0).
// Fills `px` (result, w_new, alpha, rectified) and updates `acc`.
void accumulate_pixel(const TaauOptions& to, const TaauConstants& k, const SampleBox& b, int C, bool hit,
                      float velocity, float lock, float* hv, float& acc, PixelResult& px) {
  if (b.samples == 0) {
    for (int c = 0; c < C; ++c) px.result[c] = hv[c];
    return;
  }
  float recon[16];
  // FSR 2: weights below FSR2_EPSILON count as none; the normalised result is deringed.
  if (b.wsum > kEpsilon) {
    for (int c = 0; c < C; ++c) recon[c] = std::clamp(b.sum[c] / b.wsum, b.lo[c], b.hi[c]);
    px.w_new = b.wsum * kLanczosWeightScale;
  } else {  // our fallback for a new sample without Lanczos weight: the box's weighted mean
    for (int c = 0; c < C; ++c) recon[c] = b.bsum[c] / b.bw;
  }
  if (!hit) {  // a new sample (FSR 2: the history is the upsampled colour)
    for (int c = 0; c < C; ++c) px.result[c] = recon[c];
    acc = px.w_new;
    px.alpha = 1.0f;
    return;
  }
  px.rectified = rectify_and_accumulate(to, b, C, velocity, k.scale_influence, lock, recon, px.w_new, hv, acc,
                                        px.alpha, px.result);
}

Image& TaauState::run(const FrameContext& f, bool history, FrameStats& stats) {
  const TaauOptions& to = taau_options(*f.options);
  Image& out = out_.next();
  const int cur = out_.index(), prv = 1 - cur;
  const int C = f.C, W = f.W, H = f.H, lw = f.lw, lh = f.lh, k = f.grid.k, sx = f.grid.sx, sy = f.grid.sy;
  const std::vector<float*> planes = payload_planes(out, g_.channels);
  const std::vector<const float*> prev_planes = payload_planes(out_.previous(), g_.channels);
  float* dbg_conf = f.debug ? out.add_channel("debug.confidence") : nullptr;
  float* dbg_disocc = f.debug ? out.add_channel("debug.disocclusion") : nullptr;
  float* dbg_grad = f.debug ? out.add_channel("debug.gradient") : nullptr;
  float* dbg_wf = f.debug ? out.add_channel("debug.wf") : nullptr;
  float* dbg_hw = f.debug ? out.add_channel("debug.historyWeight") : nullptr;
  float* dbg_conv = f.debug ? out.add_channel("debug.convergence") : nullptr;
  float* dbg_lock = f.debug ? out.add_channel("debug.lock") : nullptr;
  find_thin_features(f, to);
  const TaauConstants constants = taau_constants(k);
  const bool catmull_rom = to.history == "catmull-rom";

  std::atomic<std::size_t> hits{0};
  parallel_rows(H, [&](int y0, int y1) {
    thread_local HistoryRow hist;
    thread_local std::vector<float> fetched;
    std::size_t band_hits = 0;
    for (int Y = y0; Y < y1; ++Y) {
      const std::size_t row = std::size_t(Y) * W;
      fetch_history_row(f, history, prv, prev_planes, Y, hist, fetched);
      const int yn = std::clamp(JitterGrid::floor_div(2 * (Y - sy) + k, 2 * k), 0, lh - 1);
      for (int X = 0; X < W; ++X) {
        const std::size_t i = row + X;
        const bool hit = history && hist.hit[X] > 0;
        band_hits += hit ? 1 : 0;
        const float mxv = f.mx[i], myv = f.my[i];
        const float velocity = std::isfinite(mxv) && std::isfinite(myv) ? std::hypot(mxv, myv) : 0.0f;
        // Step 2: the 3x3 samples around the nearest one.
        const int xn = std::clamp(JitterGrid::floor_div(2 * (X - sx) + k, 2 * k), 0, lw - 1);
        // FSR 2: lerp(bias max, bias min, new sample) = 1 when new.
        const float bias = hit ? constants.bias_history : 1.0f;
        const float curve = -2.0f - std::min(1.0f, velocity / 50.0f);  // fRectificationCurveBias
        const SampleBox b = gather_samples(f, xn, yn, X, Y, bias, curve);
        float hv[16];
        for (int c = 0; c < C; ++c) hv[c] = hit ? fetched[std::size_t(c) * W + X] : 0.0f;
        if (hit && catmull_rom) catmull_rom_history(f, hist, prev_planes, X, Y, hv);
        to_ycgco_box(hv, hv, C);
        float acc = hit ? fetched[std::size_t(C) * W + X] : 0.0f;
        float lock = hit ? fetched[std::size_t(C + 1) * W + X] : 0.0f;
        float lock_luma = hit ? fetched[std::size_t(C + 2) * W + X] : 0.0f;
        PixelResult px;
        accumulate_pixel(to, constants, b, C, hit, velocity, lock, hv, acc, px);
        update_lock(f, to, hit, px.result, X, Y, px.w_new, constants.lifetime_per_weight, lock, lock_luma);
        from_ycgco_box(px.result, px.result, C);
        bool ok = true;
        for (int c = 0; c < C; ++c) ok = ok && std::abs(px.result[c]) <= 3.0e38f;  // false for NaN and Inf
        for (int c = 0; c < C; ++c) planes[c][i] = ok ? px.result[c] : 0.0f;
        acc_[cur][i] = ok ? acc : 0.0f;
        lock_[cur][i] = ok ? lock : 0.0f;
        lock_luma_[cur][i] = lock_luma;
        if (f.debug) {
          dbg_conf[i] = px.w_new;
          dbg_disocc[i] = hit ? 0.0f : 1.0f;
          dbg_grad[i] = px.rectified;
          dbg_wf[i] = 1.0f - px.alpha;
          dbg_hw[i] = acc_[cur][i];
          dbg_conv[i] = acc_[cur][i] / kMaxAccumulation;
          dbg_lock[i] = lock_[cur][i];
        }
      }
    }
    hits += band_hits;
  });
  prev_.store(f);
  stats.history_pixels = hits;
  stats.hole_pixels = std::size_t(W) * H - hits;
  return out;
}

// This frame's sample luminance (the payload's luma weights) and its thin features (step 5).
void TaauState::find_thin_features(const FrameContext& f, const TaauOptions& to) {
  const int lw = f.lw, lh = f.lh;
  low_luma_.assign(std::size_t(lw) * lh, 0.0f);
  for (int c = 0; c < f.C; ++c)
    for (std::size_t i = 0; i < low_luma_.size(); ++i)
      low_luma_[i] += f.luma[c] * (f.lvalid[i] > 0 ? f.low[c][i] : 0.0f);
  thin_.assign(low_luma_.size(), 0);
  if (to.locks)
    parallel_rows(lh, [&](int y0, int y1) {
      for (int y = y0; y < y1; ++y)
        for (int x = 0; x < lw; ++x) thin_[std::size_t(y) * lw + x] = char(thin_feature(low_luma_, lw, lh, x, y));
    });
}

// depth + N (the frame context's sample validity), payload in and out; motion, id; the previous depth and id read
// and written; the history read; weight, lock lifetime and lock luminance read and written.
std::size_t streamed_bytes(const Options&, int W, int H, int k, int C) {
  const std::size_t full = std::size_t(W) * H * 4, low = full / (std::size_t(k) * k);
  return 4 * full + C * low + C * full + 2 * full + full + 2 * (2 * full) + C * full + 3 * 2 * full;
}

}  // namespace

const MethodEntry& taau_method() {
  static const MethodEntry entry{
      .info = {.name = "taau",
               .summary = "engine-class temporal upscaler after FSR 2 / UE4 TAAU: Lanczos-2 reconstruction of the "
                          "jittered samples, depth disocclusion, YCoCg history clamp, per-pixel accumulation "
                          "weight, thin-feature locks",
               .has_state = true},
      .make_options = OptionsOf<TaauOptions>::make,
      .layers = history_method_layers,
      .implementations = {{kCpuDevice,
                           [](const Options& o, const Geometry& g) -> std::unique_ptr<MethodState> {
                             return std::make_unique<TaauState>(o, g);
                           }},
                          // taau_gpu.cpp: the same steps as GLSL kernels, the same state planes.
                          {kGpuDevice, gpu_implementation<make_taau_state_gpu>}},
      .streamed_bytes = streamed_bytes};
  return entry;
}

}  // namespace temporal::upsample
