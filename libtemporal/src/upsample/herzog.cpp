// `herzog`: spatio-temporal upsampling, seed 000 sections 3.3-3.5.
//
// Per frame, three passes (run row by row in one sweep, see HerzogFrame::build_schedule):
//  A (full resolution): spatial estimate h~ and its weight w~ (eq. 6) with the
//    image kernel k = hat g(|x(i) - x(j)|, r, min(gamma w_f, 4)) (section 3.3/3.5, the fallback below); motion-compensated fetch
//    of the history h_r, h_w (temporal/core/reproject.h); relative temporal gradient of the payload's luminance
//    (section 3.5.1), set to its maximum where the history is disoccluded (Figure 6), averaged into the
//    intermediate-resolution gradient buffer (section 4: "compute it at an intermediate resolution").
//  B (intermediate resolution): temporal filter |(0.4, 0.3, 0.2, 0.1) . (g_t .. g_t-3)| with the three
//    previous gradients motion-compensated; spatial low-pass by a box pyramid sampled trilinearly at
//    level 2.5 (the paper's mip level, counted at full resolution); w_f = a (1 - |grad|)^2 (eq. 8).
//  C (full resolution): eq. 7 blend and the bounded history update h_w := min(w~ + w_f h_w, max).
// Several loops pin their floating-point roundings (functions compiled with fp-contract=off and explicit
// std::fma): GCC fuses a * b + c depending on the surrounding code, and these loops must give the same bits
// wherever they are inlined (upsample_golden checks every output against a stored run).
//
// The kernel's fall-off needs w_f before h~ exists, and w_f needs h~ (the paper approximates h(i, t) by h~);
// we break the cycle by shaping the kernel with the previous frame's w_f at the motion-compensated position
// (0 where there is no history), and use this frame's w_f in eq. 7.
//
// The fallback (`--fallback`): section 3.3 says that for gamma = 0 "the results approach spatial upsampling" and
// section 3.5 that the method "falls back to spatial filtering", but eq. 3 at gamma = 0 is a constant kernel (a box
// over the four taps), not the spatial baseline's hat (section 3.1, [Yang et al. 2008]); the box is 0.65-1.9 dB
// below the hat on the built-in scenes (issue 15). By default k is the hat times eq. 3,
// k(i, j) = hat(x(i) - x(j)) g(||x(i) - x(j)||, r, gamma w_f): at gamma w_f = 0 it is exactly the spatial baseline's
// kernel, and as gamma w_f grows it still tends to the dirac of temporally-amortised upsampling (both factors are 1
// at distance 0). `--fallback flat` keeps eq. 3 alone, the literal reading.
#include "herzog.h"
#include "gpu_methods.h"

#include "temporal/upsample/history.h"
#include "temporal/core/parallel.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

namespace temporal::upsample {

const HerzogOptions& herzog_options(const Options& o) { return method_options<HerzogOptions>(o.per_method, "herzog"); }

namespace {

// Eq. 7 for one row and the bounded history-weight update. wf: w_f per pixel; wt: w~ (adaptive kernel);
// wc: w~' (sharp kernel, stored); hwf: h_w(i(t-1)) (0 on a miss); hr[c]: h_r(i(t-1)); p[c]: h~ in, h out.
void blend_row(int W, int C, const float* __restrict wf, const float* __restrict wt, const float* __restrict wc,
               const float* __restrict hwf, const float* const* hr, float* const* p, float* __restrict hn,
               float* __restrict hist, float max_hw) {
#pragma GCC ivdep
  for (int X = 0; X < W; ++X) {
    hist[X] = wf[X] * hwf[X];                                // w_f h_w(i(t-1))
    hn[X] = bounded_history_weight(wc[X], hist[X], max_hw);  // bounded history weight (see w~')
  }
  for (int c = 0; c < C; ++c) {
    float* __restrict pc = p[c];
    const float* __restrict hc = hr[c];
#pragma GCC ivdep
    for (int X = 0; X < W; ++X) {
      const float v = history_blend_weighted(pc[X], wt[X], hist[X], hc[X]);  // eq. 7
      // Nothing non-finite enters the history: such a pixel restarts with no weight. (Inputs are already
      // screened; this guards against overflow in extreme payloads.)
      const bool ok = std::abs(v) <= 3.0e38f;  // false for NaN and Inf
      hn[X] = ok ? hn[X] : 0.0f;
      pc[X] = ok ? v : 0.0f;
    }
  }
}

// Per-thread buffers (one chunk of rows at a time, see HerzogFrame::run): pass A's rows, the history taps, the cached
// low rows, the ring of pass A results that pass C reads a few rows later, and the rows of the w_f low-pass.
struct ChunkScratch {
  std::vector<float> w4, ekern, wfkrow, ycur, yprev, grad, rowbuf, histw, ring, wf_row, lev;
  HistoryRow hist;
  HistoryRow bseg;  // pass B: the runs of cells whose previous gradients are contiguous
  ExpandedLowRows low_rows;
  int wf_row_of = -1;  // the intermediate row wf_row was expanded from (shared by gs full rows)
};
// One per thread, shared by both phases (the ring is a few hundred KiB: allocated once).
ChunkScratch& chunk_scratch() {
  thread_local ChunkScratch ts;
  return ts;
}
// Intermediate rows per chunk of the row schedule (rounded up to the pyramid's alignment). Longer chunks leave
// fewer boundary rows (finished in a second phase from full planes) but balance worse over the threads. With
// the default mip level 2.5 a chunk has 2 boundary rows at each inner edge (28 of 512 rows at 1280x1024);
// 32, 64 and 128 measured the same within noise.
constexpr int kChunkRows = 64;

// Where pass A leaves its per-pixel results of one full row for pass C: w~, w~' (sharp kernel), h_w(i(t-1)),
// h_r(i(t-1)) per channel.
struct RowScratch {
  float* wt;
  float* wc;
  float* hwf;
  float* hr[16];
};

// Pass B for intermediate row gy: the temporal filter |(0.4, 0.3, 0.2, 0.1) . (g_t .. g_t-3)| (section 3.5.1)
// with the three previous gradients fetched at the motion-compensated cell centre (nearest); the shifted
// gradients go to cur3[0..2] and the filtered one to gf. First the index q of every cell's previous gradients
// (0 where outside: an unconditional load), then the filter in runs like HistoryRow's: where q - gx is
// constant over 16 cells or more (a pan, a still region) the previous gradients are read with contiguous
// loads instead of three gathers per cell. Same values either way.
// Compiled without FMA contraction: GCC fuses a * b + c depending on the surrounding code, so the same source
// would round differently in the two loops. Without it, every product of filtered_gradient is rounded before
// the sum, as in the single gathered loop this replaces (whose selects became masked multiplies, not fused).
[[gnu::noinline, gnu::optimize("fp-contract=off")]] void temporal_filter_row(
    int gy, int W, int H, int gs, int GW, int GH, bool history, const float* mx, const float* my,
    const float* __restrict dcur, const float* __restrict dcnt, const float* const* prev3, float* const* cur3,
    float* __restrict gf, HistoryRow& seg) {
  const float* __restrict p0 = prev3[0];
  const float* __restrict p1 = prev3[1];
  const float* __restrict p2 = prev3[2];
  float* __restrict c0 = cur3[0];
  float* __restrict c1 = cur3[1];
  float* __restrict c2 = cur3[2];
  const float fgs = float(gs), fGW = float(GW), fGH = float(GH);
  // The motion at the cell's centre pixel (row cy, every gs-th column) moves the three previous gradients.
  const int cy = std::min(H - 1, gy * gs + gs / 2);
  const float* __restrict mxr = mx + std::size_t(cy) * W;
  const float* __restrict myr = my + std::size_t(cy) * W;
  const float fcy = float(cy) + 0.5f;
  seg.offset.resize(GW);
  seg.aligned.resize(GW);
  seg.q[0].resize(GW);
  int* __restrict qv = seg.q[0].data();
  int* __restrict off = seg.offset.data();
  int* __restrict al = seg.aligned.data();
  auto index = [&](int gx, int cx, float mxv, float myv) {
    const float px = (float(cx) + 0.5f + mxv) / fgs, py = (fcy + myv) / fgs;
    const bool in = history & (px >= 0) & (py >= 0) & (px < fGW) & (py < fGH);  // false for NaN
    const int q = in ? int(py) * GW + int(px) : 0;
    qv[gx] = q;
    off[gx] = q - gx;
    al[gx] = int(in);
  };
  if (gs == 2 && W % 2 == 0) {  // the default: cx = 2 gx + 1 < W, stride-2 loads instead of two gathers
#pragma GCC ivdep
    for (int gx = 0; gx < GW; ++gx) index(gx, 2 * gx + 1, mxr[2 * gx + 1], myr[2 * gx + 1]);
  } else {
#pragma GCC ivdep
    for (int gx = 0; gx < GW; ++gx) {
      const int cx = std::min(W - 1, gx * gs + gs / 2);
      index(gx, cx, mxr[cx], myr[cx]);
    }
  }
  reproject::build_segments(seg, GW);
  for (const auto& sg : seg.segments) {
    if (sg.base >= 0) {  // every cell of the run is inside: q = base + gx
      const float* __restrict a0 = p0 + sg.base;
      const float* __restrict a1 = p1 + sg.base;
      const float* __restrict a2 = p2 + sg.base;
#pragma GCC ivdep
      for (int gx = sg.x0; gx < sg.x1; ++gx) {
        const float d0 = dcnt[gx] > 0 ? dcur[gx] / dcnt[gx] : kMaxGradient;
        const float d1 = a0[gx], d2 = a1[gx], d3 = a2[gx];
        c0[gx] = d0;
        c1[gx] = d1;
        c2[gx] = d2;
        gf[gx] = filtered_gradient(d0, d1, d2, d3);
      }
    } else {
#pragma GCC ivdep
      for (int gx = sg.x0; gx < sg.x1; ++gx) {
        const float d0 = dcnt[gx] > 0 ? dcur[gx] / dcnt[gx] : kMaxGradient;
        const int q = qv[gx];
        const bool in = al[gx] != 0;
        const float e1 = p0[q], e2 = p1[q], e3 = p2[q];  // unconditional loads (q is valid), then selects
        const float d1 = in ? e1 : kMaxGradient, d2 = in ? e2 : kMaxGradient, d3 = in ? e3 : kMaxGradient;
        c0[gx] = d0;
        c1[gx] = d1;
        c2[gx] = d2;
        gf[gx] = filtered_gradient(d0, d1, d2, d3);
      }
    }
  }
}

// The trilinear sampling of pass B split into its two bilinear halves, with the roundings of the single loop
// it replaces (GCC fused it as below; written out with std::fma and compiled without contraction so that no
// context changes them): each sampled pyramid row resampled once to the GW columns,
// h[gx] = (1 - ax) r[x0] + ax r[x1], then per intermediate row (1 - ay) h_i0 + ay h_i1. Each pyramid row
// serves several intermediate rows: half as many gathers as sampling every cell's four texels.
[[gnu::noinline, gnu::optimize("fp-contract=off")]] void resample_columns(const float* __restrict r,
                                                                          const int* __restrict x0,
                                                                          const int* __restrict x1,
                                                                          const float* __restrict ax, int n,
                                                                          float* __restrict h) {
#pragma GCC ivdep
  for (int gx = 0; gx < n; ++gx) {
    const float a = ax[gx];
    h[gx] = std::fma(1 - a, r[x0[gx]], a * r[x1[gx]]);
  }
}
[[gnu::noinline, gnu::optimize("fp-contract=off")]] void lerp_rows(const float* __restrict h0,
                                                                   const float* __restrict h1, float ay, int n,
                                                                   float* __restrict out) {
#pragma GCC ivdep
  for (int gx = 0; gx < n; ++gx) out[gx] = std::fma(1 - ay, h0[gx], ay * h1[gx]);
}

// --- State -----------------------------------------------------------------------------------------------------

// Everything herzog keeps between frames (ping-pong pairs indexed like the output pair: [cur] this frame, [prv] the
// previous one), and its per-frame scratch planes.
struct HerzogState : MethodState {
  HerzogState(const Options& o, const Geometry& g);
  Image& run(const FrameContext& f, bool history, FrameStats& stats) override;
  void save(Image& state) const override;
  Status load(const Image& state) override;

  OutputPair out;  // h (the output) of this frame and h_r of the next
  Geometry g;
  int gs = 1, GW = 0, GH = 0;        // gradient grid: full / gs
  PreviousGeometry prev;             // depth and ids of the previous frame
  std::vector<float> hw[2];          // history weight h_w (full resolution)
  std::vector<float> dhist[2][3];    // relative gradients of t-1, t-2, t-3 (gradient grid)
  std::vector<float> wf[2];          // w_f (gradient grid)
  // Scratch of one frame.
  std::vector<float> w_tilde, w_conf, hw_fetch;  // pass A results of the chunk-boundary rows (three-pass mode)
  std::vector<std::vector<float>> hr_fetch;
  std::vector<float> dcur, dcount, grad_smooth;
  std::vector<float> kern_lb, kern_ks, kern_hat;  // image-kernel tables expanded to full-resolution columns (per dy, tap)
  std::vector<std::vector<float>> pyramid;
  std::vector<int> pyr_w, pyr_h;
  std::vector<float> pyr_hx[2];  // the two sampled pyramid levels, rows resampled to the gradient's columns
};

HerzogState::HerzogState(const Options& o, const Geometry& geometry) : out(geometry), g(geometry) {
  const HerzogOptions& ho = herzog_options(o);
  const std::size_t N = std::size_t(g.W) * g.H;
  gs = std::max(1, ho.gradient_scale);
  GW = (g.W + gs - 1) / gs;
  GH = (g.H + gs - 1) / gs;
  const std::size_t GN = std::size_t(GW) * GH;
  for (auto& v : hw) v.assign(N, 0.0f);
  for (auto& a : dhist)
    for (auto& v : a) v.assign(GN, kMaxGradient);
  for (auto& v : wf) v.assign(GN, 0.0f);
  // Three-pass mode keeps pass A's results for pass C (full planes, used only by the chunk-boundary rows; see
  // the schedule below); the fused mode (lagged_wf) needs only rows.
  const std::size_t NS = ho.lagged_wf ? 0 : N;
  w_tilde.resize(NS);
  w_conf.resize(NS);
  hw_fetch.resize(NS);
  hr_fetch.resize(g.channels.size());
  for (auto& v : hr_fetch) v.resize(NS);
  dcur.resize(GN);  // zeroed row by row in pass A
  dcount.resize(GN);
  grad_smooth.resize(GN);
}

// The state file holds this frame's output (h_r of the next), h_w, the three gradients and w_f of this frame (the
// next frame's t-1..t-3 and its kernel shape) and the depth and ids.
void HerzogState::save(Image& state) const {
  const int c = out.index();
  for (const auto& ch : g.channels) put_plane(state, "history." + ch, out.current().plane(ch), g.W, g.H);
  put_plane(state, "history.weight", hw[c].data(), g.W, g.H);
  for (int t = 0; t < 3; ++t)
    put_plane(state, "gradient.t" + std::to_string(t + 1), dhist[c][t].data(), GW, GH);
  put_plane(state, "gradient.wf", wf[c].data(), GW, GH);
  put_previous(state, prev, g.W, g.H);
}

Status HerzogState::load(const Image& state) {
  Image& img = out.next();  // the next run() reads it as the previous frame's output
  const int c = out.index();
  for (const auto& ch : g.channels)
    if (Status s = get_plane(state, "history." + ch, img.plane(ch), g.W, g.H); !s) return s;
  if (Status s = get_plane(state, "history.weight", hw[c].data(), g.W, g.H); !s) return s;
  for (int t = 0; t < 3; ++t)
    if (Status s = get_plane(state, "gradient.t" + std::to_string(t + 1), dhist[c][t].data(), GW, GH); !s) return s;
  if (Status s = get_plane(state, "gradient.wf", wf[c].data(), GW, GH); !s) return s;
  return get_previous(state, prev, g.W, g.H);
}

// --- One frame --------------------------------------------------------------------------------------------------

// Trilinear sampling of the gradient pyramid: the bilinear taps and weights of every column (or row) of the
// gradient grid in one pyramid level (clamp-to-edge, texel centres at integers), computed once per frame.
struct Axis {
  std::vector<int> i0, i1;
  std::vector<float> a;
  void build(int n_out, int n_in, int level) {
    i0.resize(n_out);
    i1.resize(n_out);
    a.resize(n_out);
    const float sc = float(1 << level);
    for (int g = 0; g < n_out; ++g) {
      const float u = std::clamp((float(g) + 0.5f) / sc - 0.5f, 0.0f, float(n_in - 1));
      const int x0 = std::min(int(u), n_in - 1);
      i0[g] = x0;
      i1[g] = std::min(x0 + 1, n_in - 1);
      a[g] = u - float(x0);
    }
  }
};

// The three passes of one frame (the file comment), as one object: the constants of the frame, the set-up of the
// kernel tables, the pyramid and the row schedule, and one member per pass.
class HerzogFrame {
 public:
  HerzogFrame(HerzogState& s, const FrameContext& f, bool history);
  // Runs the schedule; returns the number of pixels with history.
  std::size_t run();

 private:
  void build_kernel_tables();
  void build_pyramid();
  void build_schedule();
  RowScratch row_scratch(ChunkScratch& ts, int Y, bool in_ring);
  void prepare(ChunkScratch& ts);
  // Pass A, split into its steps for full row Y.
  int pass_a_row(ChunkScratch& ts, int Y, const RowScratch& rs);
  void kernel_falloff_row(ChunkScratch& ts, int Y);
  void spatial_estimate_row(ChunkScratch& ts, int Y, const RowScratch& rs);
  int history_gradient_row(ChunkScratch& ts, int Y, const RowScratch& rs);
  void accumulate_gradient_row(ChunkScratch& ts, int Y);
  void fused_blend_row(ChunkScratch& ts, int Y, const RowScratch& rs);
  // Pass B and the pyramid.
  void pass_b_row(ChunkScratch& ts, int gy);
  void pyramid_row(int j, int y);
  void resample_row(int j, int i);
  void low_pass_row(ChunkScratch& ts, int gy);
  // Pass C.
  void pass_c_row(ChunkScratch& ts, int Y, const RowScratch& rs);
  void expand_wf_row(ChunkScratch& ts, int Y);
  void debug_row(int Y, const float* wt, const float* hwf, const float* wf_row);
  void finish_row(ChunkScratch& ts, int gy, bool in_ring);

  HerzogState& s;
  const FrameContext& f;
  const HerzogOptions& ho;
  const int C, W, H, k, gs, GW, GH, cur, prv;
  const bool history, fused;
  float max_hw = 0, inv_sn2 = 0, inv_sd2 = 0;
  std::vector<float*> planes;
  std::vector<const float*> prev_planes;
  float *dbg_conf = nullptr, *dbg_disocc = nullptr, *dbg_grad = nullptr, *dbg_wf = nullptr, *dbg_hw = nullptr,
        *dbg_conv = nullptr;
  float* hw_new = nullptr;
  // Pyramid: sampled levels l0 (and l0 + 1 when frac > 0) of `levels` above the gradient grid.
  int l0 = 0, levels = 0, nlev = 1;
  float frac = 0;
  Axis axx[2], axy[2];
  // Schedule: rows [lo, hi] of the gradient grid that row gy's low-pass reads; chunks; the ring of pass A rows.
  std::vector<int> lo, hi;
  std::vector<char> interior;
  int chunk = 0, nchunks = 0, ring_rows = 0;
  std::size_t ring_planes = 0;
};

HerzogFrame::HerzogFrame(HerzogState& st, const FrameContext& fc, bool history_flag)
    : s(st), f(fc), ho(herzog_options(*fc.options)), C(fc.C), W(fc.W), H(fc.H), k(fc.grid.k), gs(st.gs), GW(st.GW),
      GH(st.GH), cur(st.out.index()), prv(1 - st.out.index()), history(history_flag), fused(ho.lagged_wf) {
  max_hw = ho.max_history_weight > 0 ? ho.max_history_weight : 2.0f * float(k * k);
  inv_sn2 = 1.0f / (f.options->sigma_normal * f.options->sigma_normal);
  inv_sd2 = 1.0f / (f.sigma_d * f.sigma_d);
  Image& out = s.out.current();
  planes = payload_planes(out, s.g.channels);
  prev_planes = payload_planes(s.out.previous(), s.g.channels);
  if (f.debug) {
    dbg_conf = out.add_channel("debug.confidence");
    dbg_disocc = out.add_channel("debug.disocclusion");
    dbg_grad = out.add_channel("debug.gradient");
    dbg_wf = out.add_channel("debug.wf");
    dbg_hw = out.add_channel("debug.historyWeight");
    dbg_conv = out.add_channel("debug.convergence");
  }
  hw_new = s.hw[cur].data();
  build_kernel_tables();
  build_pyramid();
  build_schedule();
}

// log2 of the image-kernel base max(eps, 1 - dist / r) for the four taps at every offset (dx, dy) in the k x k
// cell; r is the low-resolution pixel diagonal (section 3.3). The kernel is then hat * exp2(gamma * log), with
// hat the spatial baseline's bilinear weight (--fallback spatial) or 1 (--fallback flat; see the file comment).
void HerzogFrame::build_kernel_tables() {
  const float r = float(k) * std::sqrt(2.0f);
  const bool hat_base = ho.fallback != "flat";
  std::vector<float> logb(std::size_t(4) * k * k), hat(logb.size());
  for (int j = 0; j < 4; ++j)
    for (int dy = 0; dy < k; ++dy)
      for (int dx = 0; dx < k; ++dx) {
        const float ox = float(dx - k * (j & 1)), oy = float(dy - k * (j >> 1));
        logb[std::size_t(j) * k * k + dy * k + dx] =
            std::log2(std::max(kKernelEpsilon, 1.0f - std::sqrt(ox * ox + oy * oy) / r));
        hat[std::size_t(j) * k * k + dy * k + dx] = hat_base ? hat_kernel(ox, oy, k) : 1.0f;
      }
  // The same kernel at the full fall-off min(gamma, cap) (w_f = 1): the weight a sample keeps in the history.
  std::vector<float> ksharp(logb.size());
  const float gamma_full = kernel_gamma(ho.kernel_gamma, 1.0f, ho.max_kernel_gamma);
  for (std::size_t j = 0; j < logb.size(); ++j) ksharp[j] = hat[j] * std::exp2(gamma_full * logb[j]);
  // The tables expanded to full-resolution columns, once per frame: plane (dy, j) holds the entry of tap j
  // at offset (cols.d[X], dy) for every column X, so the kernel loops read them with unit stride.
  s.kern_lb.resize(std::size_t(k) * 4 * W);
  s.kern_ks.resize(std::size_t(k) * 4 * W);
  s.kern_hat.resize(std::size_t(k) * 4 * W);
  for (int dy = 0; dy < k; ++dy)
    for (int j = 0; j < 4; ++j) {
      const std::size_t t = std::size_t(j) * k * k + std::size_t(dy) * k;
      float* __restrict elb = s.kern_lb.data() + (std::size_t(dy) * 4 + j) * W;
      float* __restrict eks = s.kern_ks.data() + (std::size_t(dy) * 4 + j) * W;
      float* __restrict eh = s.kern_hat.data() + (std::size_t(dy) * 4 + j) * W;
      for (int X = 0; X < W; ++X) {
        elb[X] = logb[t + f.cols.d[X]];
        eks[X] = ksharp[t + f.cols.d[X]];
        eh[X] = hat[t + f.cols.d[X]];
      }
    }
}

// Spatial low-pass of pass B: a box pyramid above the gradient grid (level 0 = the temporally filtered gradient),
// sampled trilinearly at the mip level.
void HerzogFrame::build_pyramid() {
  const float base_level = std::log2(float(gs));
  const float rel = std::max(0.0f, ho.gradient_mip_level - base_level);
  l0 = int(std::floor(rel));
  frac = rel - float(l0);
  levels = l0 + (frac > 0 ? 1 : 0);
  s.pyramid.resize(levels + 1);
  s.pyr_w.resize(levels + 1);
  s.pyr_h.resize(levels + 1);
  s.pyr_w[0] = GW;
  s.pyr_h[0] = GH;
  s.pyramid[0].resize(std::size_t(GW) * GH);
  for (int j = 1; j <= levels; ++j) {
    s.pyr_w[j] = std::max(1, (s.pyr_w[j - 1] + 1) / 2);
    s.pyr_h[j] = std::max(1, (s.pyr_h[j - 1] + 1) / 2);
    s.pyramid[j].resize(std::size_t(s.pyr_w[j]) * s.pyr_h[j]);
  }
  nlev = frac > 0 ? 2 : 1;
  for (int t = 0; t < nlev; ++t) {
    axx[t].build(GW, s.pyr_w[l0 + t], l0 + t);
    axy[t].build(GH, s.pyr_h[l0 + t], l0 + t);
    s.pyr_hx[t].resize(std::size_t(s.pyr_h[l0 + t]) * GW);
  }
}

// Pass C reads back everything pass A wrote (w~, w~', h_w, h_r and h~: 3 + 2C full planes); run one pass after the
// other and those planes make a round trip through DRAM. Instead each thread walks a chunk of gradient rows
// top-down and runs B, the pyramid rows and C for a row as soon as the rows it depends on are done, a few rows
// behind A, while A's results are still in its L2 cache (a ring of rows). Row gy of the low-passed gradient reads
// the gradient rows [lo[gy], hi[gy]] through the pyramid taps; rows whose range leaves their chunk (a few at each
// chunk boundary) keep A's results in full planes and are finished after every chunk is done. The values
// computed are the same as three separate passes: only the order in which rows are computed changes.
void HerzogFrame::build_schedule() {
  lo.assign(GH, 0);
  hi.assign(GH, 0);
  // Gradient rows under each pyramid row (box of 2x2 with clamp-to-edge, as pyramid_row builds it).
  std::vector<std::vector<int>> plo(levels + 1), phi(levels + 1);
  plo[0].resize(GH);
  phi[0].resize(GH);
  for (int i = 0; i < GH; ++i) plo[0][i] = phi[0][i] = i;
  for (int j = 1; j <= levels; ++j) {
    const int ph = s.pyr_h[j - 1];
    plo[j].resize(s.pyr_h[j]);
    phi[j].resize(s.pyr_h[j]);
    for (int i = 0; i < s.pyr_h[j]; ++i) {
      plo[j][i] = plo[j - 1][std::min(2 * i, ph - 1)];
      phi[j][i] = phi[j - 1][std::min(2 * i + 1, ph - 1)];
    }
  }
  for (int g = 0; g < GH; ++g) {
    lo[g] = GH;
    hi[g] = g;  // never before its own row
    for (int t = 0; t < nlev; ++t) {
      lo[g] = std::min({lo[g], plo[l0 + t][axy[t].i0[g]], plo[l0 + t][axy[t].i1[g]]});
      hi[g] = std::max({hi[g], phi[l0 + t][axy[t].i0[g]], phi[l0 + t][axy[t].i1[g]]});
    }
  }
  // Chunks of gradient rows, aligned to the pyramid's top level so that no pyramid row straddles two.
  const int align = 1 << levels;
  chunk = std::max(align, (kChunkRows + align - 1) / align * align);
  nchunks = (GH + chunk - 1) / chunk;
  interior.assign(GH, 0);
  int max_lag = 0;
  for (int g = 0; g < GH; ++g) {
    const int c0 = g / chunk * chunk, c1 = std::min(GH, c0 + chunk);
    interior[g] = char(lo[g] >= c0 && hi[g] < c1);
    max_lag = std::max(max_lag, hi[g] - g);
  }
  // Ring of pass A results for the interior rows: full row Y uses slot Y % ring_rows. Row gy is blended when A
  // has reached hi[gy] <= gy + max_lag, before A overwrites its slot (at gy + max_lag + 2).
  ring_rows = gs * (max_lag + 2);
  ring_planes = std::size_t(3 + C);
}

RowScratch HerzogFrame::row_scratch(ChunkScratch& ts, int Y, bool in_ring) {
  RowScratch rs;
  float* b = nullptr;
  if (fused)
    b = ts.rowbuf.data();
  else if (in_ring)
    b = ts.ring.data() + std::size_t(Y % ring_rows) * ring_planes * W;
  if (b) {
    rs.wt = b;
    rs.wc = b + W;
    rs.hwf = b + 2 * W;
    for (int c = 0; c < C; ++c) rs.hr[c] = b + std::size_t(3 + c) * W;
  } else {
    const std::size_t row = std::size_t(Y) * W;
    rs.wt = s.w_tilde.data() + row;
    rs.wc = s.w_conf.data() + row;
    rs.hwf = s.hw_fetch.data() + row;
    for (int c = 0; c < C; ++c) rs.hr[c] = s.hr_fetch[c].data() + row;
  }
  return rs;
}

void HerzogFrame::prepare(ChunkScratch& ts) {
  ts.low_rows.reset(W, k, f.grid.sx, C);
  ts.w4.resize(std::size_t(W) * 4);
  ts.ekern.resize(W);
  ts.wfkrow.resize(W);
  ts.histw.resize(W);
  ts.rowbuf.resize(fused ? std::size_t(W) * (3 + C) : 0);
  ts.ring.resize(fused ? 0 : std::size_t(ring_rows) * ring_planes * W);
  ts.ycur.resize(W);
  ts.yprev.resize(W);
  ts.grad.resize(W);
  ts.wf_row.resize(W);
  ts.lev.resize(std::size_t(2) * GW);
  ts.wf_row_of = -1;  // w_f changes every frame
}

// ---------------- pass A: one full row ----------------

// Kernel fall-off from the previous frame's w_f at the motion-compensated position (nearest cell of the gradient
// grid; the off-screen rule of temporal/core/reproject.h in that grid: the cell-area position inside [0, GW)).
void HerzogFrame::kernel_falloff_row(ChunkScratch& ts, int Y) {
  float* __restrict ek = ts.ekern.data();
  float* __restrict wfk_ = ts.wfkrow.data();
  if (!history) {
    std::fill(ek, ek + W, ho.min_kernel_gamma);
    std::fill(wfk_, wfk_ + W, 0.0f);
    return;
  }
  const std::size_t row = std::size_t(Y) * W;
  const float* __restrict mxr = f.mx + row;
  const float* __restrict myr = f.my + row;
  const float* __restrict wfp = s.wf[prv].data();
  const float inv_gs = 1.0f / float(gs), fGW = float(GW), fGH = float(GH), fY = float(Y) + 0.5f;
  const float gamma = ho.kernel_gamma, cap = ho.max_kernel_gamma, floor_g = ho.min_kernel_gamma;
  const int gw = GW, w = W;
#pragma GCC ivdep
  for (int X = 0; X < w; ++X) {
    float px = (float(X) + 0.5f + mxr[X]) * inv_gs, py = (fY + myr[X]) * inv_gs;
    const bool in = (px >= 0) & (py >= 0) & (px < fGW) & (py < fGH);  // false for NaN
    px = in ? px : 0.0f;
    py = in ? py : 0.0f;
    const float wfk = in ? wfp[int(py) * gw + int(px)] : 0.0f;
    wfk_[X] = wfk;
    ek[X] = std::max(floor_g, kernel_gamma(gamma, wfk, cap));  // section 3.5, floored
  }
}

// h~ and w~ (eq. 6) with the adaptive image kernel, and w~' (the same weights with the sharp kernel, stored in
// the history).
void HerzogFrame::spatial_estimate_row(ChunkScratch& ts, int Y, const RowScratch& rs) {
  const int w = W, kk = k;
  float* __restrict w00 = ts.w4.data();
  float* __restrict w01 = w00 + w;
  float* __restrict w10 = w01 + w;
  float* __restrict w11 = w10 + w;
  const std::size_t row = std::size_t(Y) * w;
  const int r0 = f.rows.i0[Y] * f.lw, r1 = f.rows.i1[Y] * f.lw;
  const int dy = f.rows.d[Y];
  const float* __restrict lb0 = s.kern_lb.data() + (std::size_t(dy) * 4 + 0) * w;
  const float* __restrict lb1 = s.kern_lb.data() + (std::size_t(dy) * 4 + 1) * w;
  const float* __restrict lb2 = s.kern_lb.data() + (std::size_t(dy) * 4 + 2) * w;
  const float* __restrict lb3 = s.kern_lb.data() + (std::size_t(dy) * 4 + 3) * w;
  const float* __restrict ks0 = s.kern_ks.data() + (std::size_t(dy) * 4 + 0) * w;
  const float* __restrict ks1 = s.kern_ks.data() + (std::size_t(dy) * 4 + 1) * w;
  const float* __restrict ks2 = s.kern_ks.data() + (std::size_t(dy) * 4 + 2) * w;
  const float* __restrict ks3 = s.kern_ks.data() + (std::size_t(dy) * 4 + 3) * w;
  const float* __restrict kh0 = s.kern_hat.data() + (std::size_t(dy) * 4 + 0) * w;
  const float* __restrict kh1 = s.kern_hat.data() + (std::size_t(dy) * 4 + 1) * w;
  const float* __restrict kh2 = s.kern_hat.data() + (std::size_t(dy) * 4 + 2) * w;
  const float* __restrict kh3 = s.kern_hat.data() + (std::size_t(dy) * 4 + 3) * w;
  // The two low rows' samples expanded to the full-resolution columns (cached over the k rows using them).
  const float *e0 = nullptr, *e1 = nullptr;
  ts.low_rows.get(f, r0, r1, e0, e1);
  const float* __restrict ekr = ts.ekern.data();
  // Expanded plane q, tap t of low row e (see ExpandedLowRows).
  const std::size_t es = ts.low_rows.stride();
  auto ex = [es, kk](const float* e, int q, int t) { return e + std::size_t(q) * es + std::size_t(t) * kk; };
  // Geometric weights of the four taps (normal and depth tents, cubed, times tap existence).
  expanded_geometric_weights(f, inv_sn2, inv_sd2, Y, e0, e1, es, w00, w01, w10, w11);
  float* __restrict wt = rs.wt;
  float* __restrict wc = rs.wc;
  // History confidence of this frame's samples: the same weights with the sharp kernel (w_f = 1).
#pragma GCC ivdep
  for (int X = 0; X < w; ++X) wc[X] = w00[X] * ks0[X] + w01[X] * ks1[X] + w10[X] * ks2[X] + w11[X] * ks3[X];
  // The adaptive image kernel, in a loop of its own: fused with the geometry above, the loop body is too
  // large for GCC's if-conversion and the whole loop stays scalar.
#pragma GCC ivdep
  for (int X = 0; X < w; ++X) {
    const float e = ekr[X];
    w00[X] = w00[X] * (kh0[X] * fast_exp2(e * lb0[X]));
    w01[X] = w01[X] * (kh1[X] * fast_exp2(e * lb1[X]));
    w10[X] = w10[X] * (kh2[X] * fast_exp2(e * lb2[X]));
    w11[X] = w11[X] * (kh3[X] * fast_exp2(e * lb3[X]));
    wt[X] = w00[X] + w01[X] + w10[X] + w11[X];
  }
  for (int c = 0; c < C; ++c) {  // eq. 6
    const float* __restrict l00 = ex(e0, 5 + c, 0);
    const float* __restrict l01 = ex(e0, 5 + c, 1);
    const float* __restrict l10 = ex(e1, 5 + c, 0);
    const float* __restrict l11 = ex(e1, 5 + c, 1);
    float* __restrict o_ = planes[c] + row;
#pragma GCC ivdep
    for (int X = 0; X < w; ++X) {
      // Unconditional loads, then a select (an invalid sample's value may be NaN: it must not propagate).
      const float la = l00[X], lb = l01[X], lc = l10[X], ld = l11[X];
      const float a = w00[X] > 0 ? la : 0.0f, b = w01[X] > 0 ? lb : 0.0f;
      const float cc = w10[X] > 0 ? lc : 0.0f, d = w11[X] > 0 ? ld : 0.0f;
      const float v = w00[X] * a + w01[X] * b + w10[X] * cc + w11[X] * d;
      o_[X] = wt[X] > 0 ? v / wt[X] : 0.0f;
    }
  }
}

// History fetch at i(t-1) (h_w and h_r) and the relative temporal gradient of the luminance (section 3.5.1), the
// maximum where the history is disoccluded (Figure 6). Returns the number of pixels with history.
int HerzogFrame::history_gradient_row(ChunkScratch& ts, int Y, const RowScratch& rs) {
  const int w = W;
  float* __restrict hwf = rs.hwf;
  if (!history) {
    std::fill(hwf, hwf + w, 0.0f);
    for (int c = 0; c < C; ++c) std::fill(rs.hr[c], rs.hr[c] + w, 0.0f);
    std::fill(ts.grad.begin(), ts.grad.end(), kMaxGradient);
    return 0;
  }
  const std::size_t row = std::size_t(Y) * w;
  HistoryRow& hist = ts.hist;
  history_row(f, s.prev, Y, hist);
  {
    const float* src[9];
    float* dst[9];
    int n = 0;
    src[n] = s.hw[prv].data();
    dst[n++] = hwf;
    for (int c = 0; c < C; ++c) {
      src[n] = prev_planes[c];
      dst[n++] = rs.hr[c];
      if (n == 4 || c == C - 1) {
        reproject::gather_row(hist, src, dst, n, w);
        n = 0;
      }
    }
  }
  float* __restrict yc = ts.ycur.data();
  float* __restrict yp = ts.yprev.data();
  std::fill(yc, yc + w, 0.0f);
  std::fill(yp, yp + w, 0.0f);
  for (int c = 0; c < C; ++c) {
    float* hr = rs.hr[c];
    const float lc = f.luma[c];
    const float* __restrict cur_c = planes[c] + row;
#pragma GCC ivdep
    for (int X = 0; X < w; ++X) {
      yc[X] += lc * cur_c[X];
      yp[X] += lc * hr[X];
    }
  }
  const float* __restrict hit = hist.hit.data();
  const float* __restrict wt = rs.wt;
  float* __restrict gr = ts.grad.data();
#pragma GCC ivdep
  for (int X = 0; X < w; ++X) {
    const float g = std::clamp(relative_gradient(yc[X], yp[X]), -kMaxGradient, kMaxGradient);
    // Disoccluded (no history) or no spatial sample: the maximum gradient (Figure 6).
    gr[X] = (hit[X] > 0 && wt[X] > 0) ? g : kMaxGradient;
  }
  int row_hits = 0;
  for (int X = 0; X < w; ++X) row_hits += int(hit[X] > 0);  // an int reduction vectorises
  return row_hits;
}

// Average into the gradient grid (its row is zeroed before its first full row).
void HerzogFrame::accumulate_gradient_row(ChunkScratch& ts, int Y) {
  float* dc = s.dcur.data() + std::size_t(Y / gs) * GW;
  float* dn = s.dcount.data() + std::size_t(Y / gs) * GW;
  int gx_full = 0;
  if (gs == 2) {  // the default: whole cells in a loop that vectorises (same sums, same order)
    const float* __restrict gr = ts.grad.data();
    float* __restrict dc_ = dc;
    float* __restrict dn_ = dn;
    gx_full = W / 2;
#pragma GCC ivdep
    for (int gx = 0; gx < gx_full; ++gx) {
      dc_[gx] += (0.0f + gr[2 * gx]) + gr[2 * gx + 1];
      dn_[gx] += 2.0f;
    }
  }
  for (int gx = gx_full; gx < GW; ++gx) {
    float sum = 0.0f;
    int n = 0;
    for (int X = gx * gs; X < std::min(W, gx * gs + gs); ++X, ++n) sum += ts.grad[X];
    dc[gx] += sum;
    dn[gx] += float(n);
  }
}

// --lagged-wf: eq. 7 with the previous frame's w_f at the motion-compensated position (the one that shaped k).
void HerzogFrame::fused_blend_row(ChunkScratch& ts, int Y, const RowScratch& rs) {
  const std::size_t row = std::size_t(Y) * W;
  float* prow[16];
  for (int c = 0; c < C; ++c) prow[c] = planes[c] + row;
  blend_row(W, C, ts.wfkrow.data(), rs.wt, rs.wc, rs.hwf, rs.hr, prow, hw_new + row, ts.histw.data(), max_hw);
  if (dbg_conf) debug_row(Y, rs.wt, rs.hwf, ts.wfkrow.data());
}

int HerzogFrame::pass_a_row(ChunkScratch& ts, int Y, const RowScratch& rs) {
  kernel_falloff_row(ts, Y);
  spatial_estimate_row(ts, Y, rs);
  const int row_hits = history_gradient_row(ts, Y, rs);
  accumulate_gradient_row(ts, Y);
  if (fused) fused_blend_row(ts, Y, rs);
  return row_hits;
}

// ---------------- pass B: temporal filter of one gradient row (pyramid level 0) ----------------

void HerzogFrame::pass_b_row(ChunkScratch& ts, int gy) {
  const std::size_t grow = std::size_t(gy) * GW;
  const float* prev3[3] = {s.dhist[prv][0].data(), s.dhist[prv][1].data(), s.dhist[prv][2].data()};
  float* cur3[3] = {s.dhist[cur][0].data() + grow, s.dhist[cur][1].data() + grow, s.dhist[cur][2].data() + grow};
  temporal_filter_row(gy, W, H, gs, GW, GH, history, f.mx, f.my, s.dcur.data() + grow, s.dcount.data() + grow,
                      prev3, cur3, s.pyramid[0].data() + grow, ts.bseg);
  if (ho.gradient_filter == "none") {  // ablation: this frame's gradient alone, |g_t| (the history still shifts)
    float* __restrict gf = s.pyramid[0].data() + grow;
    const float* __restrict g0 = cur3[0];
    for (int gx = 0; gx < GW; ++gx) gf[gx] = std::abs(g0[gx]);
  }
}

// Pyramid level j, row y: 2x2 box of level j - 1 (clamp-to-edge).
void HerzogFrame::pyramid_row(int j, int y) {
  const int pw = s.pyr_w[j - 1], ph = s.pyr_h[j - 1], w = s.pyr_w[j];
  float* __restrict dst = s.pyramid[j].data() + std::size_t(y) * w;
  const float* __restrict src = s.pyramid[j - 1].data();
  const int ya = std::min(2 * y, ph - 1), yb = std::min(2 * y + 1, ph - 1);
  for (int x = 0; x < w; ++x) {
    const int xa = std::min(2 * x, pw - 1), xb = std::min(2 * x + 1, pw - 1);
    dst[x] = 0.25f * (src[std::size_t(ya) * pw + xa] + src[std::size_t(ya) * pw + xb] +
                      src[std::size_t(yb) * pw + xa] + src[std::size_t(yb) * pw + xb]);
  }
}

// Level l0 + t of the pyramid, row i, resampled to the GW columns (the sampled levels only).
void HerzogFrame::resample_row(int j, int i) {
  const int t = j - l0;
  if (t < 0 || t >= nlev) return;
  resample_columns(s.pyramid[j].data() + std::size_t(i) * s.pyr_w[j], axx[t].i0.data(), axx[t].i1.data(),
                   axx[t].a.data(), GW, s.pyr_hx[t].data() + std::size_t(i) * GW);
}

// Trilinear sample of the pyramid for one gradient row, and eq. 8.
void HerzogFrame::low_pass_row(ChunkScratch& ts, int gy) {
  const int gw = GW;
  for (int t = 0; t < nlev; ++t) {
    const float* hx = s.pyr_hx[t].data();
    lerp_rows(hx + std::size_t(axy[t].i0[gy]) * gw, hx + std::size_t(axy[t].i1[gy]) * gw, axy[t].a[gy], gw,
              ts.lev.data() + std::size_t(t) * gw);
  }
  const float* __restrict g0 = ts.lev.data();
  const float* __restrict g1 = ts.lev.data() + gw;
  float* __restrict gsm = s.grad_smooth.data() + std::size_t(gy) * gw;
  float* __restrict wfo = s.wf[cur].data() + std::size_t(gy) * gw;
  const float a_ = ho.sensitivity(), fr = frac;
  if (nlev == 2) {
#pragma GCC ivdep
    for (int gx = 0; gx < gw; ++gx) {
      const float g = (1 - fr) * g0[gx] + fr * g1[gx];
      gsm[gx] = g;
      wfo[gx] = temporal_weight(g, a_);  // eq. 8
    }
  } else {
#pragma GCC ivdep
    for (int gx = 0; gx < gw; ++gx) {
      gsm[gx] = g0[gx];
      wfo[gx] = temporal_weight(g0[gx], a_);  // eq. 8
    }
  }
  if (ho.fixed_wf >= 0.0f) std::fill(wfo, wfo + gw, ho.fixed_wf);  // ablation: no adaptation, w_f constant
}

// ---------------- pass C: eq. 7 for one full row ----------------

// w_f of each gradient cell repeated over its gs columns (shared by the gs full rows of the cell).
void HerzogFrame::expand_wf_row(ChunkScratch& ts, int Y) {
  if (Y / gs == ts.wf_row_of) return;
  float* wf_row = ts.wf_row.data();
  const float* wfr = s.wf[cur].data() + std::size_t(Y / gs) * GW;
  int gx0 = 0;
  if (gs == 2) {  // the default, in a loop that vectorises
    gx0 = W / 2;
    float* __restrict d = wf_row;
    const float* __restrict sw = wfr;
    for (int gx = 0; gx < gx0; ++gx) {
      d[2 * gx] = sw[gx];
      d[2 * gx + 1] = sw[gx];
    }
  }
  for (int gx = gx0; gx < GW; ++gx)
    for (int X = gx * gs; X < std::min(W, gx * gs + gs); ++X) wf_row[X] = wfr[gx];
  ts.wf_row_of = Y / gs;
}

void HerzogFrame::debug_row(int Y, const float* wt, const float* hwf, const float* wf_row) {
  const std::size_t row = std::size_t(Y) * W;
  for (int X = 0; X < W; ++X) {
    dbg_conf[row + X] = wt[X];
    dbg_disocc[row + X] = hwf[X] > 0 ? 0.0f : 1.0f;
    dbg_wf[row + X] = wf_row[X];
    dbg_hw[row + X] = hw_new[row + X];
    dbg_conv[row + X] = hw_new[row + X] / max_hw;
  }
}

void HerzogFrame::pass_c_row(ChunkScratch& ts, int Y, const RowScratch& rs) {
  const std::size_t row = std::size_t(Y) * W;
  if (dbg_grad) {
    const float* gsr = s.grad_smooth.data() + std::size_t(Y / gs) * GW;
    for (int X = 0; X < W; ++X) dbg_grad[row + X] = gsr[X / gs];
  }
  if (fused) return;  // eq. 7 already ran in pass A
  expand_wf_row(ts, Y);
  float* p[16];
  for (int c = 0; c < C; ++c) p[c] = planes[c] + row;
  blend_row(W, C, ts.wf_row.data(), rs.wt, rs.wc, rs.hwf, rs.hr, p, hw_new + row, ts.histw.data(), max_hw);
  if (dbg_conf) debug_row(Y, rs.wt, rs.hwf, ts.wf_row.data());
}

// Low-pass and eq. 7 for every full row of gradient row gy.
void HerzogFrame::finish_row(ChunkScratch& ts, int gy, bool in_ring) {
  low_pass_row(ts, gy);
  for (int Y = gy * gs; Y < std::min(H, gy * gs + gs); ++Y) pass_c_row(ts, Y, row_scratch(ts, Y, in_ring));
}

std::size_t HerzogFrame::run() {
  // Phase 1: chunks in parallel; in each, A, B and the pyramid row by row, C for the interior rows.
  std::atomic<std::size_t> hits{0};
  parallel_rows(nchunks, [&](int ch0, int ch1) {
    ChunkScratch& ts = chunk_scratch();
    std::size_t band_hits = 0;
    for (int ch = ch0; ch < ch1; ++ch) {
      prepare(ts);
      const int c0 = ch * chunk, c1 = std::min(GH, c0 + chunk);
      int next = c0;  // the next low-passed row to finish
      for (int gy = c0; gy < c1; ++gy) {
        std::fill_n(s.dcur.data() + std::size_t(gy) * GW, GW, 0.0f);
        std::fill_n(s.dcount.data() + std::size_t(gy) * GW, GW, 0.0f);
        const bool in_ring = interior[gy] != 0;
        for (int Y = gy * gs; Y < std::min(H, gy * gs + gs); ++Y)
          band_hits += std::size_t(pass_a_row(ts, Y, row_scratch(ts, Y, in_ring)));
        pass_b_row(ts, gy);
        resample_row(0, gy);
        for (int j = 1; j <= levels; ++j)  // the pyramid rows whose last source row this was
          if ((gy + 1) % (1 << j) == 0 || gy == GH - 1) {
            pyramid_row(j, gy >> j);
            resample_row(j, gy >> j);
          }
        for (; next < c1 && hi[next] <= gy; ++next)  // hi never decreases (monotone taps): rows in order
          if (interior[next]) finish_row(ts, next, true);
      }
    }
    hits += band_hits;
  }, 1);
  // Phase 2: the rows whose low-pass reaches into a neighbouring chunk.
  std::vector<int> boundary;
  for (int g = 0; g < GH; ++g)
    if (!interior[g]) boundary.push_back(g);
  parallel_rows(int(boundary.size()), [&](int b0, int b1) {
    ChunkScratch& ts = chunk_scratch();
    prepare(ts);
    for (int b = b0; b < b1; ++b) finish_row(ts, boundary[b], false);
  });
  return hits;
}

Image& HerzogState::run(const FrameContext& f, bool history, FrameStats& stats) {
  Image& img = out.next();
  const std::size_t hits = HerzogFrame(*this, f, history).run();
  prev.store(f);
  stats.history_pixels = hits;
  stats.hole_pixels = std::size_t(g.W) * g.H - hits;
  return img;
}

// --- Registry entry --------------------------------------------------------------------------------------------

// depth + N, payload in and out; motion, id; the previous depth and id read and written; the history read; h_w
// read and written.
std::size_t streamed_bytes(const Options&, int W, int H, int k, int C) {
  const std::size_t full = std::size_t(W) * H * 4, low = full / (std::size_t(k) * k);
  return 4 * full + C * low + C * full + 2 * full + full + 2 * (2 * full) + C * full + 2 * full;
}

// The gradient grid's size depends on --gradient-scale.
std::string state_layout(const Options& o) { return "gradient-scale " + std::to_string(herzog_options(o).gradient_scale); }

}  // namespace

const MethodEntry& herzog_method() {
  static const MethodEntry entry{
      .info = {.name = "herzog",
               .summary = "spatio-temporal upsampling (seed 000 sections 3.3-3.5): exponential history (eq. 6-7), "
                          "adaptive image kernel, w_f from the filtered relative gradient (eq. 8)",
               .has_state = true,
               .variants = {{"herzog-lagged", "herzog", {"--lagged-wf"},
                             "eq. 7 with the previous frame's w_f: one fused pass"},
                            {"herzog-favor-spatial", "herzog", {"--favor-spatial"},
                             "a = 0.7 (the paper's elephant scene)"}}},
      .make_options = OptionsOf<HerzogOptions>::make,
      .layers = history_method_layers,
      .implementations = {{kCpuDevice,
                           [](const Options& o, const Geometry& g) -> std::unique_ptr<MethodState> {
                             return std::make_unique<HerzogState>(o, g);
                           }},
                          // herzog_gpu.cpp: the same passes as GLSL kernels, the same state planes.
                          {kGpuDevice, gpu_implementation<make_herzog_state_gpu>}},
      .streamed_bytes = streamed_bytes,
      .state_layout = state_layout};
  return entry;
}

}  // namespace temporal::upsample
