// `herzog`: spatio-temporal upsampling, seed 000 sections 3.3-3.5.
//
// Per frame, three passes:
//  A (full resolution, bands of gradient rows): spatial estimate h~ and its weight w~ (eq. 6) with the
//    image kernel k = g(|x(i) - x(j)|, r, min(gamma w_f, 4)) (section 3.3/3.5); motion-compensated fetch
//    of the history h_r, h_w (reprojection.h); relative temporal gradient of the payload's luminance
//    (section 3.5.1), set to its maximum where the history is disoccluded (Figure 6), averaged into the
//    intermediate-resolution gradient buffer (section 4: "compute it at an intermediate resolution").
//  B (intermediate resolution): temporal filter |(0.4, 0.3, 0.2, 0.1) . (g_t .. g_t-3)| with the three
//    previous gradients motion-compensated; spatial low-pass by a box pyramid sampled trilinearly at
//    level 2.5 (the paper's mip level, counted at full resolution); w_f = a (1 - |grad|)^2 (eq. 8).
//  C (full resolution): eq. 7 blend and the bounded history update h_w := min(w~ + w_f h_w, max).
//
// The kernel's fall-off needs w_f before h~ exists, and w_f needs h~ (the paper approximates h(i, t) by h~);
// we break the cycle by shaping the kernel with the previous frame's w_f at the motion-compensated position
// (0 where there is no history: a flat kernel, i.e. spatial upsampling), and use this frame's w_f in eq. 7.
#include "upsample_internal.h"

#include "temporal/history.h"
#include "temporal/parallel.h"

#include <atomic>
#include <cmath>

namespace temporal::upsample {
namespace {

// Bilinear clamp-to-edge sample of a w x h plane at texel coordinates (u, v) (texel centres at integers).
float sample_bilinear(const std::vector<float>& p, int w, int h, float u, float v) {
  u = std::clamp(u, 0.0f, float(w - 1));
  v = std::clamp(v, 0.0f, float(h - 1));
  const int x0 = std::min(int(u), w - 1), y0 = std::min(int(v), h - 1);
  const int x1 = std::min(x0 + 1, w - 1), y1 = std::min(y0 + 1, h - 1);
  const float ax = u - float(x0), ay = v - float(y0);
  const float a = p[std::size_t(y0) * w + x0], b = p[std::size_t(y0) * w + x1];
  const float c = p[std::size_t(y1) * w + x0], d = p[std::size_t(y1) * w + x1];
  return (1 - ay) * ((1 - ax) * a + ax * b) + ay * ((1 - ax) * c + ax * d);
}

// Eq. 7 for one row and the bounded history-weight update. wf: w_f per pixel; wt: w~ (adaptive kernel);
// wc: w~' (sharp kernel, stored); hwf: h_w(i(t-1)) (0 on a miss); hr[c]: h_r(i(t-1)); p[c]: h~ in, h out.
void blend_row(int W, int C, const float* __restrict wf, const float* __restrict wt, const float* __restrict wc,
               const float* __restrict hwf, const float* const* hr, float* const* p, float* __restrict hn,
               float* __restrict hist, float max_hw) {
#pragma GCC ivdep
  for (int X = 0; X < W; ++X) {
    hist[X] = wf[X] * hwf[X];                    // w_f h_w(i(t-1))
    hn[X] = std::min(wc[X] + hist[X], max_hw);  // bounded history weight (see w~')
  }
  for (int c = 0; c < C; ++c) {
    float* __restrict pc = p[c];
    const float* __restrict hc = hr[c];
#pragma GCC ivdep
    for (int X = 0; X < W; ++X) {
      const float den = wt[X] + hist[X];
      const float v = den > 0 ? (pc[X] * wt[X] + hist[X] * hc[X]) / den : pc[X];
      // Nothing non-finite enters the history: such a pixel restarts with no weight. (Inputs are already
      // screened; this guards against overflow in extreme payloads.)
      const bool ok = std::abs(v) <= 3.0e38f;  // false for NaN and Inf
      hn[X] = ok ? hn[X] : 0.0f;
      pc[X] = ok ? v : 0.0f;
    }
  }
}

}  // namespace

void run_herzog(Upsampler::State& s, const FrameContext& f, const Options& o, FrameStats& stats) {
  const int C = f.C, W = f.W, H = f.H, k = f.grid.k;
  const std::size_t N = std::size_t(W) * H;
  const int gs = std::max(1, o.gradient_scale);
  const int GW = (W + gs - 1) / gs, GH = (H + gs - 1) / gs;
  const std::size_t GN = std::size_t(GW) * GH;
  const int cur = s.cur, prv = 1 - s.cur;
  const bool history = s.have_history && s.GW == GW && s.GH == GH && s.hw[prv].size() == N;
  s.GW = GW;
  s.GH = GH;
  for (auto& v : s.hw) v.resize(N, 0.0f);
  // Three-pass mode keeps pass A's results for pass C; the fused mode (o.lagged_wf) needs only rows.
  const bool fused = o.lagged_wf;
  const std::size_t NS = fused ? 0 : N;
  s.w_tilde.resize(NS);
  s.w_conf.resize(NS);
  s.hw_fetch.resize(NS);
  s.hr_fetch.resize(C);
  for (auto& v : s.hr_fetch) v.resize(NS);
  s.dcur.assign(GN, 0.0f);
  s.dcount.assign(GN, 0.0f);
  for (auto& a : s.dhist)
    for (auto& v : a) v.resize(GN, kMaxGradient);
  s.gfilt.resize(GN);
  s.grad_smooth.resize(GN);
  for (auto& v : s.wf) v.resize(GN, 0.0f);
  const float max_hw = o.max_history_weight > 0 ? o.max_history_weight : 2.0f * float(k * k);

  Image& out = s.result[cur];
  const Image& prev = s.result[prv];
  std::vector<float*> planes;
  std::vector<const float*> prev_planes;
  for (const auto& c : s.channels) {
    planes.push_back(out.plane(c));
    prev_planes.push_back(prev.plane(c));
  }

  // log2 of the image-kernel base max(eps, 1 - dist / r) for the four taps at every offset (dx, dy) in the
  // k x k cell; r is the low-resolution pixel diagonal (section 3.3). The kernel is then exp2(gamma * log).
  const float r = float(k) * std::sqrt(2.0f);
  std::vector<float> logb(std::size_t(4) * k * k);
  for (int j = 0; j < 4; ++j)
    for (int dy = 0; dy < k; ++dy)
      for (int dx = 0; dx < k; ++dx) {
        const float ox = float(dx - k * (j & 1)), oy = float(dy - k * (j >> 1));
        logb[std::size_t(j) * k * k + dy * k + dx] =
            std::log2(std::max(kKernelEpsilon, 1.0f - std::sqrt(ox * ox + oy * oy) / r));
      }
  // The same kernel at the full fall-off min(gamma, cap) (w_f = 1): the weight a sample keeps in the history.
  std::vector<float> ksharp(logb.size());
  const float gamma_full = kernel_gamma(o.kernel_gamma, 1.0f, o.max_kernel_gamma);
  for (std::size_t j = 0; j < logb.size(); ++j) ksharp[j] = std::exp2(gamma_full * logb[j]);
  const float inv_sn2 = 1.0f / (o.sigma_normal * o.sigma_normal), inv_sd2 = 1.0f / (f.sigma_d * f.sigma_d);
  const std::vector<float>& wf_prev = s.wf[prv];

  float* dbg_conf = o.debug_layers ? out.add_channel("debug.confidence") : nullptr;
  float* dbg_disocc = o.debug_layers ? out.add_channel("debug.disocclusion") : nullptr;
  float* dbg_grad = o.debug_layers ? out.add_channel("debug.gradient") : nullptr;
  float* dbg_wf = o.debug_layers ? out.add_channel("debug.wf") : nullptr;
  float* dbg_hw = o.debug_layers ? out.add_channel("debug.historyWeight") : nullptr;
  float* dbg_conv = o.debug_layers ? out.add_channel("debug.convergence") : nullptr;
  float* hw_new = s.hw[cur].data();

  // ---------------- pass A ----------------
  std::atomic<std::size_t> hits{0};
  parallel_rows(GH, [&](int gy0, int gy1) {
    thread_local std::vector<float> w4, ekern, wfkrow, ycur, yprev, grad, rowbuf, histw;
    thread_local HistoryRow hist;
    w4.resize(std::size_t(W) * 4);
    ekern.resize(W);
    wfkrow.resize(W);
    histw.resize(W);
    rowbuf.resize(fused ? std::size_t(W) * (3 + C) : 0);
    ycur.resize(W);
    yprev.resize(W);
    grad.resize(W);
    float* __restrict w00 = w4.data();
    float* __restrict w01 = w00 + W;
    float* __restrict w10 = w01 + W;
    float* __restrict w11 = w10 + W;
    std::size_t band_hits = 0;
    for (int Y = gy0 * gs; Y < std::min(H, gy1 * gs); ++Y) {
      const std::size_t row = std::size_t(Y) * W;
      const int r0 = s.rows.i0[Y] * f.lw, r1 = s.rows.i1[Y] * f.lw;
      const float vy0 = s.rows.v0[Y], vy1 = s.rows.v1[Y];
      const int dy = s.rows.d[Y];
      const float* lb0 = logb.data() + std::size_t(0) * k * k + dy * k;
      const float* lb1 = logb.data() + std::size_t(1) * k * k + dy * k;
      const float* lb2 = logb.data() + std::size_t(2) * k * k + dy * k;
      const float* lb3 = logb.data() + std::size_t(3) * k * k + dy * k;
      // Kernel fall-off from the previous frame's w_f at the motion-compensated position.
      {
        float* __restrict ek = ekern.data();
        float* __restrict wfk_ = wfkrow.data();
        if (history) {
          const float* __restrict mxr = f.mx + row;
          const float* __restrict myr = f.my + row;
          const float* __restrict wfp = wf_prev.data();
          const float inv_gs = 1.0f / float(gs), fGW = float(GW), fGH = float(GH), fY = float(Y) + 0.5f;
          const float gamma = o.kernel_gamma, cap = o.max_kernel_gamma, floor_g = o.min_kernel_gamma;
          const int gw = GW;
#pragma GCC ivdep
          for (int X = 0; X < W; ++X) {
            float px = (float(X) + 0.5f + mxr[X]) * inv_gs, py = (fY + myr[X]) * inv_gs;
            const bool in = (px >= 0) & (py >= 0) & (px < fGW) & (py < fGH);  // false for NaN
            px = in ? px : 0.0f;
            py = in ? py : 0.0f;
            const float wfk = in ? wfp[int(py) * gw + int(px)] : 0.0f;
            wfk_[X] = wfk;
            ek[X] = std::max(floor_g, std::min(gamma * wfk, cap));  // kernel_gamma(), floored
          }
        } else {
          std::fill(ek, ek + W, o.min_kernel_gamma);
          std::fill(wfk_, wfk_ + W, 0.0f);
        }
      }
      const float* __restrict z = f.z + row;
      const float* __restrict nx = f.nx + row;
      const float* __restrict ny = f.ny + row;
      const float* __restrict nz = f.nz + row;
      const float* __restrict lz = s.lz.data();
      const float* __restrict lnx = s.lnx.data();
      const float* __restrict lny = s.lny.data();
      const float* __restrict lnz = s.lnz.data();
      const float* __restrict lvalid = s.lvalid.data();
      const int* __restrict ci0 = s.cols.i0.data();
      const int* __restrict ci1 = s.cols.i1.data();
      const int* __restrict cd = s.cols.d.data();
      const float* __restrict cv0 = s.cols.v0.data();
      const float* __restrict cv1 = s.cols.v1.data();
      const float* __restrict ekr = ekern.data();
      auto geo = [=](int j, float zi, float ax, float ay, float az) {
        const float dot = ax * lnx[j] + ay * lny[j] + az * lnz[j];
        const float xn = std::max(0.0f, 1.0f - dot);
        const float tn = std::max(kKernelEpsilon, 1.0f - xn * xn * inv_sn2);
        const float dz = zi - lz[j];
        const float td = std::max(kKernelEpsilon, 1.0f - dz * dz * inv_sd2);
        const float w = tn * tn * tn * td * td * td * lvalid[j];
        return w >= 0.0f ? w : 0.0f;
      };
      const float* ks0 = ksharp.data() + std::size_t(0) * k * k + dy * k;
      const float* ks1 = ksharp.data() + std::size_t(1) * k * k + dy * k;
      const float* ks2 = ksharp.data() + std::size_t(2) * k * k + dy * k;
      const float* ks3 = ksharp.data() + std::size_t(3) * k * k + dy * k;
      // Pass A's per-pixel results: whole planes for pass C, or rows when eq. 7 runs here (fused).
      float* __restrict wt = fused ? rowbuf.data() : s.w_tilde.data() + row;
      float* __restrict wc = fused ? rowbuf.data() + W : s.w_conf.data() + row;
      float* hwf_row = fused ? rowbuf.data() + 2 * W : s.hw_fetch.data() + row;
      float* hr_rows[16];
      for (int c = 0; c < C; ++c) hr_rows[c] = fused ? rowbuf.data() + std::size_t(3 + c) * W : s.hr_fetch[c].data() + row;
#pragma GCC ivdep
      for (int X = 0; X < W; ++X) {
        const int dx = cd[X], i0 = ci0[X], i1 = ci1[X];
        const float zi = z[X], ax = nx[X], ay = ny[X], az = nz[X];
        const float g00 = geo(r0 + i0, zi, ax, ay, az) * cv0[X] * vy0;
        const float g01 = geo(r0 + i1, zi, ax, ay, az) * cv1[X] * vy0;
        const float g10 = geo(r1 + i0, zi, ax, ay, az) * cv0[X] * vy1;
        const float g11 = geo(r1 + i1, zi, ax, ay, az) * cv1[X] * vy1;
        w00[X] = g00;
        w01[X] = g01;
        w10[X] = g10;
        w11[X] = g11;
        // History confidence of this frame's samples: the same weights with the sharp kernel (w_f = 1).
        wc[X] = g00 * ks0[dx] + g01 * ks1[dx] + g10 * ks2[dx] + g11 * ks3[dx];
      }
      // The adaptive image kernel, in a loop of its own: fused with the geometry above, the loop body is too
      // large for GCC's if-conversion and the whole loop stays scalar.
#pragma GCC ivdep
      for (int X = 0; X < W; ++X) {
        const int dx = cd[X];
        const float e = ekr[X];
        w00[X] = w00[X] * fast_exp2(e * lb0[dx]);
        w01[X] = w01[X] * fast_exp2(e * lb1[dx]);
        w10[X] = w10[X] * fast_exp2(e * lb2[dx]);
        w11[X] = w11[X] * fast_exp2(e * lb3[dx]);
        wt[X] = w00[X] + w01[X] + w10[X] + w11[X];
      }
      for (int c = 0; c < C; ++c) {  // eq. 6
        const float* __restrict l0 = f.low[c] + r0;
        const float* __restrict l1 = f.low[c] + r1;
        float* __restrict o_ = planes[c] + row;
#pragma GCC ivdep
        for (int X = 0; X < W; ++X) {
          const int i0 = ci0[X], i1 = ci1[X];
          // Unconditional loads (the indices are clamped, always valid), then a select: conditional loads
          // would need masked gathers, which keep the loop scalar.
          const float la = l0[i0], lb = l0[i1], lc = l1[i0], ld = l1[i1];
          const float a = w00[X] > 0 ? la : 0.0f, b = w01[X] > 0 ? lb : 0.0f;
          const float cc = w10[X] > 0 ? lc : 0.0f, d = w11[X] > 0 ? ld : 0.0f;
          const float v = w00[X] * a + w01[X] * b + w10[X] * cc + w11[X] * d;
          o_[X] = wt[X] > 0 ? v / wt[X] : 0.0f;
        }
      }
      // History fetch at i(t-1) and the relative temporal gradient (section 3.5.1).
      float* __restrict hwf = hwf_row;
      float* __restrict yc = ycur.data();
      float* __restrict yp = yprev.data();
      if (history) {
        history_row(s, f, o, Y, hist);
        {
          const float* src[9];
          float* dst[9];
          int n = 0;
          src[n] = s.hw[prv].data();
          dst[n++] = hwf;
          for (int c = 0; c < C; ++c) {
            src[n] = prev_planes[c];
            dst[n++] = hr_rows[c];
            if (n == 4 || c == C - 1) {
              gather_history_planes(hist, src, dst, n, W);
              n = 0;
            }
          }
        }
        std::fill(yc, yc + W, 0.0f);
        std::fill(yp, yp + W, 0.0f);
        for (int c = 0; c < C; ++c) {
          float* hr = hr_rows[c];
          const float lc = f.luma[c];
          const float* __restrict cur_c = planes[c] + row;
#pragma GCC ivdep
          for (int X = 0; X < W; ++X) {
            yc[X] += lc * cur_c[X];
            yp[X] += lc * hr[X];
          }
        }
        const float* __restrict hit = hist.hit.data();
        float* __restrict gr = grad.data();
#pragma GCC ivdep
        for (int X = 0; X < W; ++X) {
          const float g = std::clamp(relative_gradient(yc[X], yp[X]), -kMaxGradient, kMaxGradient);
          // Disoccluded (no history) or no spatial sample: the maximum gradient (Figure 6).
          gr[X] = (hit[X] > 0 && wt[X] > 0) ? g : kMaxGradient;
        }
        for (int X = 0; X < W; ++X) band_hits += hit[X] > 0 ? 1 : 0;
      } else {
        std::fill(hwf, hwf + W, 0.0f);
        for (int c = 0; c < C; ++c) std::fill(hr_rows[c], hr_rows[c] + W, 0.0f);
        std::fill(grad.begin(), grad.end(), kMaxGradient);
      }
      // Average into the intermediate-resolution gradient buffer.
      float* dc = s.dcur.data() + std::size_t(Y / gs) * GW;
      float* dn = s.dcount.data() + std::size_t(Y / gs) * GW;
      for (int gx = 0; gx < GW; ++gx) {
        float sum = 0.0f;
        int n = 0;
        for (int X = gx * gs; X < std::min(W, gx * gs + gs); ++X, ++n) sum += grad[X];
        dc[gx] += sum;
        dn[gx] += float(n);
      }
      if (fused) {
        // Eq. 7 with the previous frame's w_f at the motion-compensated position (the one that shaped k).
        float* prow[16];
        for (int c = 0; c < C; ++c) prow[c] = planes[c] + row;
        blend_row(W, C, wfkrow.data(), wt, wc, hwf, hr_rows, prow, hw_new + row, histw.data(), max_hw);
        if (dbg_conf)
          for (int X = 0; X < W; ++X) {
            dbg_conf[row + X] = wt[X];
            dbg_disocc[row + X] = hwf[X] > 0 ? 0.0f : 1.0f;
            dbg_wf[row + X] = wfkrow[X];
            dbg_hw[row + X] = hw_new[row + X];
            dbg_conv[row + X] = hw_new[row + X] / max_hw;
          }
      }
    }
    hits += band_hits;
  });

  // ---------------- pass B ----------------
  auto& dh_prev = s.dhist[prv];
  auto& dh_cur = s.dhist[cur];
  parallel_rows(GH, [&](int gy0, int gy1) {
    for (int gy = gy0; gy < gy1; ++gy)
      for (int gx = 0; gx < GW; ++gx) {
        const std::size_t g = std::size_t(gy) * GW + gx;
        const float d0 = s.dcount[g] > 0 ? s.dcur[g] / s.dcount[g] : kMaxGradient;
        float d1 = kMaxGradient, d2 = kMaxGradient, d3 = kMaxGradient;
        if (history) {
          const int cx = std::min(W - 1, gx * gs + gs / 2), cy = std::min(H - 1, gy * gs + gs / 2);
          const std::size_t i = std::size_t(cy) * W + cx;
          const float px = (float(cx) + 0.5f + f.mx[i]) / float(gs), py = (float(cy) + 0.5f + f.my[i]) / float(gs);
          if (px >= 0 && py >= 0 && px < float(GW) && py < float(GH)) {
            const std::size_t q = std::size_t(py) * GW + std::size_t(px);
            d1 = dh_prev[0][q];
            d2 = dh_prev[1][q];
            d3 = dh_prev[2][q];
          }
        }
        dh_cur[0][g] = d0;
        dh_cur[1][g] = d1;
        dh_cur[2][g] = d2;
        s.gfilt[g] = filtered_gradient(d0, d1, d2, d3);
      }
  });
  // Spatial low-pass: box pyramid above the intermediate level, sampled trilinearly at the mip level.
  const float base_level = std::log2(float(gs));
  const float rel = std::max(0.0f, o.gradient_mip_level - base_level);
  const int l0 = int(std::floor(rel));
  const float frac = rel - float(l0);
  const int levels = l0 + (frac > 0 ? 1 : 0);
  s.pyramid.resize(levels + 1);
  s.pyr_w.resize(levels + 1);
  s.pyr_h.resize(levels + 1);
  s.pyramid[0] = s.gfilt;
  s.pyr_w[0] = GW;
  s.pyr_h[0] = GH;
  for (int j = 1; j <= levels; ++j) {
    const int pw = s.pyr_w[j - 1], ph = s.pyr_h[j - 1];
    const int w = std::max(1, (pw + 1) / 2), h = std::max(1, (ph + 1) / 2);
    s.pyr_w[j] = w;
    s.pyr_h[j] = h;
    auto& dst = s.pyramid[j];
    const auto& src = s.pyramid[j - 1];
    dst.resize(std::size_t(w) * h);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const int xa = std::min(2 * x, pw - 1), xb = std::min(2 * x + 1, pw - 1);
        const int ya = std::min(2 * y, ph - 1), yb = std::min(2 * y + 1, ph - 1);
        dst[std::size_t(y) * w + x] = 0.25f * (src[std::size_t(ya) * pw + xa] + src[std::size_t(ya) * pw + xb] +
                                               src[std::size_t(yb) * pw + xa] + src[std::size_t(yb) * pw + xb]);
      }
  }
  parallel_rows(GH, [&](int gy0, int gy1) {
    for (int gy = gy0; gy < gy1; ++gy)
      for (int gx = 0; gx < GW; ++gx) {
        auto at = [&](int j) {
          const float sc = float(1 << j);
          return sample_bilinear(s.pyramid[j], s.pyr_w[j], s.pyr_h[j], (float(gx) + 0.5f) / sc - 0.5f,
                                 (float(gy) + 0.5f) / sc - 0.5f);
        };
        float g = at(l0);
        if (frac > 0) g = (1 - frac) * g + frac * at(l0 + 1);
        const std::size_t q = std::size_t(gy) * GW + gx;
        s.grad_smooth[q] = g;
        s.wf[cur][q] = temporal_weight(g, o.a);  // eq. 8
      }
  });

  // ---------------- pass C ----------------
  const std::vector<float>& wf_cur = s.wf[cur];
  parallel_rows(H, [&](int y0, int y1) {
    thread_local std::vector<float> wf_row, hist_w;
    wf_row.resize(W);
    hist_w.resize(W);
    for (int Y = y0; Y < y1; ++Y) {
      const std::size_t row = std::size_t(Y) * W;
      const float* wfr = wf_cur.data() + std::size_t(Y / gs) * GW;
      if (dbg_grad) {
        const float* gsr = s.grad_smooth.data() + std::size_t(Y / gs) * GW;
        for (int X = 0; X < W; ++X) dbg_grad[row + X] = gsr[X / gs];
      }
      if (fused) continue;  // eq. 7 already ran in pass A
      for (int gx = 0; gx < GW; ++gx)
        for (int X = gx * gs; X < std::min(W, gx * gs + gs); ++X) wf_row[X] = wfr[gx];
      const float* hr[16];
      float* p[16];
      for (int c = 0; c < C; ++c) {
        hr[c] = s.hr_fetch[c].data() + row;
        p[c] = planes[c] + row;
      }
      blend_row(W, C, wf_row.data(), s.w_tilde.data() + row, s.w_conf.data() + row, s.hw_fetch.data() + row, hr, p,
                hw_new + row, hist_w.data(), max_hw);
      if (dbg_conf) {
        for (int X = 0; X < W; ++X) {
          dbg_conf[row + X] = s.w_tilde[row + X];
          dbg_disocc[row + X] = s.hw_fetch[row + X] > 0 ? 0.0f : 1.0f;
          dbg_wf[row + X] = wf_row[X];
          dbg_hw[row + X] = hw_new[row + X];
          dbg_conv[row + X] = hw_new[row + X] / max_hw;
        }
      }
    }
  });
  stats.history_pixels = hits;
  stats.hole_pixels = N - hits;
}

}  // namespace temporal::upsample
