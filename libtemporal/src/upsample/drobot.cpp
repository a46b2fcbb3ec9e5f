// `drobot`: the spatiotemporal framework of seed 002 (Drobot 2011), in the order of its "Spatiotemporal
// Coherency" list:
//   1-2. caching at the low (shading) resolution with a history buffer HB and a current buffer CB;
//   3.   CB = this frame's samples;
//   4.   HB accumulated into CB by reprojection caching (Listing 7.2: bilinear depth, cache miss when the
//        depth differs; exponential history h(t) = h(t-1) w + r (1 - w) with a running convergence);
//   5.   the per-pixel convergence factor is kept;
//   6.   CB bilaterally filtered (Listing 7.3, separable), more strongly where convergence is low;
//   7.   CB bilaterally upsampled to full resolution (Listing 7.1, precomputed bilinear weight table);
//   8.   CB becomes HB (the filtered buffer is the history: "we were switching history buffers after
//        bilateral filtering").
// `DrobotMode::Refresh` is the refresh-buffer reconstruction of Figure 7.12: a full-resolution history,
// the 1/n refresh buffer written at its pixels, and Listing 7.1 upsampling where neither has the pixel.
//
// The low-resolution samples of successive frames sit at different sub-pixel positions (the regular
// pattern). The cache stores one value per k x k block (its centre), so that, as in Figure 7.6, each frame
// adds one subset of the block's samples and a static cache is never resampled; repeated resampling of a
// jittered grid blurs it (measured: 7 px of blur at k = 4, docs/upsample-st.md).
#include "drobot_options.h"
#include "gpu_methods.h"

#include "temporal/upsample/drobot.h"
#include "temporal/core/parallel.h"

#include <atomic>

namespace temporal::upsample {

const DrobotOptions& drobot_options(const Options& o) { return method_options<DrobotOptions>(o.per_method, "drobot"); }

namespace {

// Everything drobot keeps between frames: the low-resolution cache (cache mode, ping-pong) or the full-resolution
// history and depth (refresh mode), and the per-frame scratch of the filter and the cache grid.
struct DrobotState : MethodState {
  DrobotState(const Options& o, const Geometry& g);
  Image& run(const FrameContext& f, bool history, FrameStats& stats) override;
  void save(Image& state) const override;
  Status load(const Image& state) override;

  const DrobotOptions& opt;
  OutputPair out;
  Geometry g;
  // cache mode: low-resolution history (value, depth, frame count), ping-pong, and filter scratch.
  std::vector<std::vector<float>> hb_val[2];
  std::vector<float> hb_z[2], hb_n[2];
  std::vector<std::uint32_t> hb_id[2];  // the blocks' material ids (empty without ids)
  std::vector<std::vector<float>> cb_val, cb_tmp;
  std::vector<float> cb_conf, cb_hit, cb_w, cb_strength, cb_avail, cb_avail_h;
  // cache grid: one sample per k x k block at its centre: geometry, id, and motion in cache texels.
  TapTable cache_cols, cache_rows;
  std::vector<float> cz, czw, cnx, cny, cnz, cmx, cmy, cache_table;  // czw: prevDepth.Z (empty without)
  std::vector<std::uint32_t> cid;
  // refresh mode: the previous depth (and ids), Listing 7.1's bilinear table.
  PreviousGeometry prev;
  std::vector<float> bilinear_table;
};

// Listing 7.1 for full-resolution row Y from low-resolution planes src[c] with availability `avail` (0/1),
// into out[c] (row pointers); `wsum` receives the sum of weights.
// Where the coarse samples are: tap tables, their geometry and the bilinear table.
struct CoarseGrid {
  const TapTable& cols;
  const TapTable& rows;
  const float *lz, *lnx, *lny, *lnz;
  const float* table;
};

void drobot_upsample_row(const CoarseGrid& gr, const FrameContext& f, const DrobotOptions& o, int Y,
                         const std::vector<const float*>& src, const float* avail_, float* const* out, float* wsum) {
  thread_local std::vector<float> w4;
  w4.resize(std::size_t(f.W) * 4);
  float* __restrict w00 = w4.data();
  float* __restrict w01 = w00 + f.W;
  float* __restrict w10 = w01 + f.W;
  float* __restrict w11 = w10 + f.W;
  const int W = f.W, k = f.grid.k;
  const int r0 = gr.rows.i0[Y] * f.lw, r1 = gr.rows.i1[Y] * f.lw;
  const float vy0 = gr.rows.v0[Y], vy1 = gr.rows.v1[Y];
  const float* __restrict table = gr.table + std::size_t(gr.rows.d[Y]) * k * 4;
  const std::size_t row = std::size_t(Y) * W;
  const float inv_range = 1.0f / f.depth_range;
  const bool normals = !o.depth_only;
  const float power = o.normal_power;
  const float* __restrict lz = gr.lz;
  const float* __restrict lnx = gr.lnx;
  const float* __restrict lny = gr.lny;
  const float* __restrict lnz = gr.lnz;
  const float* __restrict avail = avail_;
  const int* __restrict ci0 = gr.cols.i0.data();
  const int* __restrict ci1 = gr.cols.i1.data();
  const int* __restrict cd = gr.cols.d.data();
  const float* __restrict cv0 = gr.cols.v0.data();
  const float* __restrict cv1 = gr.cols.v1.data();
  const float* __restrict z = f.z + row;
  const float* __restrict nx = f.nx + row;
  const float* __restrict ny = f.ny + row;
  const float* __restrict nz = f.nz + row;
  const bool pow32 = power == 32.0f;  // the default contrast: five squarings instead of exp2(32 log2(dot))
  auto geo = [=](int j, float zi, float ax, float ay, float az) {
    // pow(dot, contrastCoef) (Listing 7.1), or 1 for the depth-only variant.
    const float dot = std::max(1e-8f, ax * lnx[j] + ay * lny[j] + az * lnz[j]);
    float d2 = dot * dot;
    d2 *= d2;
    d2 *= d2;
    d2 *= d2;
    d2 *= d2;
    const float nw = normals ? (pow32 ? d2 : fast_exp2(power * fast_log2(dot))) : 1.0f;
    const float w = nw / (kDrobotDepthBias + std::abs(zi - lz[j]) * inv_range) * avail[j];
    return w >= 0.0f ? w : 0.0f;
  };
#pragma GCC ivdep
  for (int X = 0; X < W; ++X) {
    const float* t = table + std::size_t(cd[X]) * 4;
    const int i0 = ci0[X], i1 = ci1[X];
    const float zi = z[X], ax = nx[X], ay = ny[X], az = nz[X];
    w00[X] = geo(r0 + i0, zi, ax, ay, az) * t[0] * cv0[X] * vy0;
    w01[X] = geo(r0 + i1, zi, ax, ay, az) * t[1] * cv1[X] * vy0;
    w10[X] = geo(r1 + i0, zi, ax, ay, az) * t[2] * cv0[X] * vy1;
    w11[X] = geo(r1 + i1, zi, ax, ay, az) * t[3] * cv1[X] * vy1;
  }
  for (int c = 0; c < f.C; ++c) {
    const float* __restrict l0 = src[c] + r0;
    const float* __restrict l1 = src[c] + r1;
    float* __restrict o_ = out[c];
#pragma GCC ivdep
    for (int X = 0; X < W; ++X) {
      const int i0 = ci0[X], i1 = ci1[X];
      const float ws = w00[X] + w01[X] + w10[X] + w11[X];
      const float a = w00[X] > 0 ? l0[i0] : 0.0f, b = w01[X] > 0 ? l0[i1] : 0.0f;
      const float cc = w10[X] > 0 ? l1[i0] : 0.0f, d = w11[X] > 0 ? l1[i1] : 0.0f;
      // No usable coarse sample at all: the plain bilinear value (from whatever the buffer holds).
      const float* t = table + std::size_t(cd[X]) * 4;
      const float t0 = t[0] * cv0[X] * vy0, t1 = t[1] * cv1[X] * vy0, t2 = t[2] * cv0[X] * vy1, t3 = t[3] * cv1[X] * vy1;
      const float ts = t0 + t1 + t2 + t3;
      const float fallback = ts > 0 ? (t0 * l0[i0] + t1 * l0[i1] + t2 * l1[i0] + t3 * l1[i1]) / ts : 0.0f;
      const float fb = std::abs(fallback) <= 3.0e38f ? fallback : 0.0f;
      o_[X] = ws > 0 ? (w00[X] * a + w01[X] * b + w10[X] * cc + w11[X] * d) / ws : fb;
    }
  }
  if (wsum)
    for (int X = 0; X < W; ++X) wsum[X] = w00[X] + w01[X] + w10[X] + w11[X];
}

// One direction of Listing 7.3 over a w x h low-resolution plane. Taps at +-1.5 and +-3.5 texels read
// the mean of two texels, as the hardware linear filter does; depth is filtered the same way.
// `strength` in [0, 1] scales the four side taps (0 leaves the pixel unchanged). Texels are counted by
// their availability `avail` (0 for a block without any sample of its own surface yet), so such a block
// is reconstructed from its neighbours ("when a pixel lacks samples ... it is reconstructed from spatial
// coherency data"); `avail_out` says whether anything reached the texel.
void bilateral_pass(const float* src, const float* z, const float* strength, const float* avail, int w, int h,
                    bool horizontal, float amp, float* dst, float* avail_out) {
  parallel_rows(h, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < w; ++x) {
        const std::size_t i = std::size_t(y) * w + x;
        auto at = [&](const float* p, int o) {
          const int xx = horizontal ? std::clamp(x + o, 0, w - 1) : x;
          const int yy = horizontal ? y : std::clamp(y + o, 0, h - 1);
          return p[std::size_t(yy) * w + xx];
        };
        const float zc = z[i];
        const float inv_z = zc > 0 ? 1.0f / zc : 0.0f;
        const float s_i = avail[i] > 0 ? strength[i] : 1.0f;
        float sum = kDrobotCenterWeight * avail[i] * src[i], wsum = kDrobotCenterWeight * avail[i];
        static constexpr int kPair[4][2] = {{-3, -4}, {-1, -2}, {1, 2}, {3, 4}};
        for (int t = 0; t < 4; ++t) {
          const float a0 = at(avail, kPair[t][0]), a1 = at(avail, kPair[t][1]);
          if (a0 + a1 <= 0.0f) continue;
          const float v = (a0 * at(src, kPair[t][0]) + a1 * at(src, kPair[t][1])) / (a0 + a1);
          const float zt = (a0 * at(z, kPair[t][0]) + a1 * at(z, kPair[t][1])) / (a0 + a1);
          const float wt = 0.5f * (a0 + a1) * s_i *
                           drobot_filter_tap_weight(zc * inv_z, zt * inv_z, amp, kDrobotTapWeights[t]);
          sum += wt * v;
          wsum += wt;
        }
        dst[i] = wsum > 0 ? sum / wsum : src[i];
        avail_out[i] = wsum > 0 ? 1.0f : 0.0f;
      }
  });
}

// The cache grid: low-resolution pixel x stands for its k x k block, at the block's centre
// (k x + k/2 in full-resolution coordinates, a pixel corner for even k). Its geometry is the G-buffer at
// pixel (k x + k/2, k y + k/2). Accumulating the jittered samples of k*k frames there is the sample-set
// amortisation of Figure 7.6; the cache is never resampled in a static scene.
void build_cache_grid(DrobotState& s, const FrameContext& f) {
  const int k = f.grid.k, lw = f.lw, lh = f.lh;
  s.cache_cols.build(f.W, lw, k, k / 2);
  s.cache_rows.build(f.H, lh, k, k / 2);
  if (s.cache_table.size() != std::size_t(k) * k * 4) {
    // Listing 7.1's table for the block centres: offset d of pixel X from the sample pixel k x + k/2 is
    // a distance of d + 0.5 pixels from the block centre for even k.
    const float off = (k % 2 == 0) ? 0.5f : 0.0f;
    s.cache_table.resize(std::size_t(k) * k * 4);
    for (int dy = 0; dy < k; ++dy)
      for (int dx = 0; dx < k; ++dx) {
        const float fx = (float(dx) + off) / float(k), fy = (float(dy) + off) / float(k);
        float* e = &s.cache_table[std::size_t(dy * k + dx) * 4];
        e[0] = (1 - fx) * (1 - fy);
        e[1] = fx * (1 - fy);
        e[2] = (1 - fx) * fy;
        e[3] = fx * fy;
      }
  }
  const std::size_t LN = std::size_t(lw) * lh;
  s.cz.resize(LN);
  s.czw.resize(f.prev_z ? LN : 0);
  s.cnx.resize(LN);
  s.cny.resize(LN);
  s.cnz.resize(LN);
  s.cmx.resize(LN);
  s.cmy.resize(LN);
  s.cid.resize(f.id ? LN : 0);
  const float inv_k = 1.0f / float(k);
  for (int y = 0; y < lh; ++y)
    for (int x = 0; x < lw; ++x) {
      const std::size_t j = std::size_t(y) * lw + x;
      const std::size_t i = std::size_t(std::min(f.H - 1, k * y + k / 2)) * f.W + std::min(f.W - 1, k * x + k / 2);
      s.cz[j] = f.z[i];
      if (f.prev_z) s.czw[j] = f.prev_z[i];
      s.cnx[j] = f.nx[i];
      s.cny[j] = f.ny[i];
      s.cnz[j] = f.nz[i];
      // The block centre moves with the motion of its representative pixel: p_prev = p + motion is, in cache
      // texels (centres at integers), x + motion / k.
      s.cmx[j] = f.mx[i] * inv_k;
      s.cmy[j] = f.my[i] * inv_k;
      if (f.id) s.cid[j] = f.id[i];
    }
}

// Listing 7.2's cache-miss test, the paper's own validity test, on top of the reprojection module's rules. First
// the listing's cached depth for one row of n pixels: the bilinear filter of the previous depth plane at the fetch
// position (x + mx, y + my) over all four taps, edges repeated (reproject::bilinear's value: the listing's hardware
// filter reads every tap, whatever surface it shows). The taps are those of `h` (reproject_row: the same clamped
// indices); a loop that vectorises. Pixels whose fetch missed get a value that is not used.
void listing72_depth_row(const HistoryRow& h, const float* __restrict prev_z, const float* __restrict mx,
                         const float* __restrict my, int y, int n, float* __restrict out) {
  const int* __restrict q0 = h.q[0].data();
  const int* __restrict q1 = h.q[1].data();
  const int* __restrict q2 = h.q[2].data();
  const int* __restrict q3 = h.q[3].data();
  const float fy = float(y);
#pragma GCC ivdep
  for (int x = 0; x < n; ++x) {
    const float u = float(x) + mx[x], v = fy + my[x];
    const float tx = u - reproject::floor_vec(u), ty = v - reproject::floor_vec(v);
    out[x] = (1.0f - tx) * (1.0f - ty) * prev_z[q0[x]] + tx * (1.0f - ty) * prev_z[q1[x]] +
             (1.0f - tx) * ty * prev_z[q2[x]] + tx * ty * prev_z[q3[x]];
  }
}

// Then the confidence: 0 where the module's fetch misses (off screen, or no tap of the same surface), else
// 1 - saturate((|z - zc| / z - threshold) * convergenceTime) (drobot.h).
inline float cache_confidence(float hit, float z, float zc, float threshold, float convergence_time) {
  return hit > 0 ? drobot_cache_confidence(z > 0 ? (z - zc) / z : 1.0f, threshold, convergence_time, true) : 0.0f;
}

// Steps 3-5 of the framework for cache row y: this frame's samples accumulated into the reprojected cache HB
// (Listing 7.2 on the reprojection module's fetch in the cache grid, exponential history with the running
// convergence). Returns the blocks whose cache hit.
std::size_t accumulate_cache_row(DrobotState& s, const FrameContext& f, bool history, int y, HistoryRow& h,
                                 std::vector<float>& fetched) {
  const DrobotOptions& o = s.opt;
  const int C = f.C, k = f.grid.k, lw = f.lw, cur = s.out.index(), prv = 1 - cur;
  const float nmax = o.max_frames > 0 ? o.max_frames : float(k * k);
  const std::size_t row = std::size_t(y) * lw;
  // The module's fetch in the cache grid: off-screen rule, bilinear taps, per-tap depth / id test; the frame
  // count and the values are read from the surviving taps.
  fetched.resize(std::size_t(2 + C) * lw);
  float* nc = fetched.data();
  float* zc = nc + lw;
  auto fetched_value = [&](int c) { return fetched.data() + std::size_t(2 + c) * lw; };
  if (history) {
    reproject::Frames fr;
    fr.width = lw;
    fr.height = f.lh;
    fr.motion_x = s.cmx.data();
    fr.motion_y = s.cmy.data();
    fr.prev_z = s.hb_z[prv].data();
    fr.id = s.cid.empty() ? nullptr : s.cid.data();
    fr.prev_id = s.hb_id[prv].empty() ? nullptr : s.hb_id[prv].data();
    fr.test = f.options->surface_test();
    reproject::expect_depth(fr, s.cz.data(), s.czw.empty() ? nullptr : s.czw.data(), f.options->warped_depth_tolerance);
    reproject::reproject_row(fr, y, h);
    if (o.cache_point) {  // Figure 7.5's point filtering: the surviving tap with the largest weight
      for (int x = 0; x < lw; ++x) {
        int best = 0;
        for (int t = 1; t < 4; ++t) best = h.w[t][x] > h.w[best][x] ? t : best;
        const int q = h.q[best][x];
        nc[x] = s.hb_n[prv][q];
        for (int c = 0; c < C; ++c) fetched_value(c)[x] = s.hb_val[prv][c][q];
      }
    } else {
      const float* src[1 + 16] = {s.hb_n[prv].data()};
      float* dst[1 + 16] = {nc};
      for (int c = 0; c < C; ++c) {
        src[1 + c] = s.hb_val[prv][c].data();
        dst[1 + c] = fetched_value(c);
      }
      reproject::gather_row(h, src, dst, 1 + C, lw);
    }
    listing72_depth_row(h, s.hb_z[prv].data(), s.cmx.data() + row, s.cmy.data() + row, y, lw, zc);
  } else {
    h.resize(lw);
    std::fill(h.hit.begin(), h.hit.end(), 0.0f);
  }
  std::size_t hits = 0;
  for (int x = 0; x < lw; ++x) {
    const std::size_t j = row + x;
    const float z = s.cz[j];
    const float conf = cache_confidence(h.hit[x], z, zc[x], o.miss_threshold, o.convergence_time);
    const float n_prev = conf > 0 ? nc[x] : 0.0f;
    hits += conf > 0 ? 1 : 0;
    float n_new = 0.0f;
    const float w = drobot_convergence_weight(n_prev, conf, nmax, &n_new);
    // This frame's sample lies at sub-pixel (sx, sy) of the block: it is accumulated only when it shows the
    // block's surface (same relative-depth test as the cache), so a block straddling a silhouette does not mix
    // the two surfaces. A non-finite sample never enters the history.
    const float zs = f.z[std::size_t(k * y + f.grid.sy) * f.W + (k * x + f.grid.sx)];
    const bool finite = f.lvalid[j] > 0;
    const bool valid = finite && z > 0 && std::abs(zs - z) <= o.miss_threshold * z;
    const float n = valid ? n_new : n_prev * conf;
    for (int c = 0; c < C; ++c) {
      const float hist = conf > 0 ? fetched_value(c)[x] : 0.0f;
      float value = valid ? exponential_history(hist, f.low[c][j], w) : hist;
      if (n <= 0.0f) value = finite ? f.low[c][j] : 0.0f;  // nothing of this surface yet (filter fills it)
      s.cb_val[c][j] = value;
    }
    s.hb_n[cur][j] = n;
    s.hb_z[cur][j] = z;
    if (!s.cid.empty()) s.hb_id[cur][j] = s.cid[j];
    s.cb_hit[j] = conf;
    s.cb_w[j] = n > 0 ? 1.0f : 0.0f;
    s.cb_conf[j] = std::min(1.0f, n / nmax);  // convergence factor (step 5)
    s.cb_strength[j] = 1.0f - s.cb_conf[j];
  }
  return hits;
}

// Step 7: Listing 7.1 upsampling of the filtered CB (now the cache) from the block centres, and the debug layers.
void upsample_cache(DrobotState& s, const FrameContext& f, Image& out) {
  const int C = f.C, k = f.grid.k, lw = f.lw, lh = f.lh, cur = s.out.index();
  const std::vector<float*> planes = payload_planes(out, s.g.channels);
  std::vector<const float*> src;
  for (int c = 0; c < C; ++c) src.push_back(s.hb_val[cur][c].data());
  float* dbg_conf = f.debug ? out.add_channel("debug.confidence") : nullptr;
  float* dbg_disocc = f.debug ? out.add_channel("debug.disocclusion") : nullptr;
  float* dbg_conv = f.debug ? out.add_channel("debug.convergence") : nullptr;
  float* dbg_hw = f.debug ? out.add_channel("debug.historyWeight") : nullptr;
  const CoarseGrid grid{s.cache_cols, s.cache_rows, s.cz.data(), s.cnx.data(), s.cny.data(), s.cnz.data(),
                        s.cache_table.data()};
  parallel_rows(f.H, [&](int y0, int y1) {
    std::vector<float*> rows(C);
    for (int Y = y0; Y < y1; ++Y) {
      const std::size_t row = std::size_t(Y) * f.W;
      for (int c = 0; c < C; ++c) rows[c] = planes[c] + row;
      drobot_upsample_row(grid, f, s.opt, Y, src, s.cb_avail.data(), rows.data(), dbg_conf ? dbg_conf + row : nullptr);
      if (!dbg_disocc) continue;
      const int ly = std::clamp(Y / k, 0, lh - 1);  // the block the pixel lies in
      for (int X = 0; X < f.W; ++X) {
        const std::size_t j = std::size_t(ly) * lw + std::clamp(X / k, 0, lw - 1);
        dbg_disocc[row + X] = s.cb_hit[j] > 0 ? 0.0f : 1.0f;
        dbg_conv[row + X] = s.cb_conf[j];
        dbg_hw[row + X] = s.hb_n[cur][j];
      }
    }
  });
}

Image& run_cache(DrobotState& s, const FrameContext& f, bool have_history, FrameStats& stats) {
  const int C = f.C, k = f.grid.k, lw = f.lw, lh = f.lh;
  const std::size_t LN = std::size_t(lw) * lh;
  Image& out = s.out.next();
  const int cur = s.out.index(), prv = 1 - cur;
  for (auto& hv : s.hb_val) {
    hv.resize(C);
    for (auto& v : hv) v.resize(LN, 0.0f);
  }
  for (auto& v : s.hb_z) v.resize(LN, 0.0f);
  for (auto& v : s.hb_n) v.resize(LN, 0.0f);
  for (auto& v : s.hb_id) v.resize(f.id ? LN : 0, 0u);
  for (auto* v : {&s.cb_val, &s.cb_tmp}) {
    v->resize(C);
    for (auto& p : *v) p.resize(LN);
  }
  for (auto* v : {&s.cb_conf, &s.cb_hit, &s.cb_w, &s.cb_strength, &s.cb_avail, &s.cb_avail_h}) v->resize(LN);
  build_cache_grid(s, f);
  const bool history = have_history && s.hb_z[prv].size() == LN;
  std::atomic<std::size_t> hits{0};
  parallel_rows(lh, [&](int y0, int y1) {
    thread_local HistoryRow h;
    thread_local std::vector<float> fetched;
    std::size_t band_hits = 0;
    for (int y = y0; y < y1; ++y) band_hits += accumulate_cache_row(s, f, history, y, h, fetched);
    hits += band_hits;
  });
  // Step 6: Listing 7.3, horizontal then vertical, strength 1 - convergence; result is the new HB (step 8).
  for (int c = 0; c < C; ++c) {
    bilateral_pass(s.cb_val[c].data(), s.hb_z[cur].data(), s.cb_strength.data(), s.cb_w.data(), lw, lh, true,
                   s.opt.filter_amp, s.cb_tmp[c].data(), s.cb_avail_h.data());
    bilateral_pass(s.cb_tmp[c].data(), s.hb_z[cur].data(), s.cb_strength.data(), s.cb_avail_h.data(), lw, lh, false,
                   s.opt.filter_amp, s.hb_val[cur][c].data(), s.cb_avail.data());
  }
  upsample_cache(s, f, out);
  stats.history_pixels = hits * std::size_t(k) * k;
  stats.hole_pixels = (LN - hits) * std::size_t(k) * k;
  return out;
}

// Figure 7.12 for full-resolution row Y: the Listing 7.1 upsampling of the refresh buffer, this frame's samples
// where it has them, and the history where the reprojection module's fetch hits and Listing 7.2's test passes,
// blended by its confidence. Returns {holes, hits}.
std::pair<std::size_t, std::size_t> refresh_row(DrobotState& s, const FrameContext& f, bool history, int Y,
                                                float* const* rows, const std::vector<const float*>& prev_planes,
                                                HistoryRow& h, std::vector<float>& fetched, float* dbg_conf,
                                                float* dbg_disocc, float* dbg_conv) {
  const DrobotOptions& o = s.opt;
  const int C = f.C, W = f.W;
  const std::size_t row = std::size_t(Y) * W;
  // The refresh buffer's samples sit at this frame's jittered positions.
  const CoarseGrid grid{f.cols, f.rows, f.lz.data(), f.lnx.data(), f.lny.data(), f.lnz.data(),
                        s.bilinear_table.data()};
  drobot_upsample_row(grid, f, o, Y, f.low, f.lvalid.data(), rows, dbg_conf ? dbg_conf + row : nullptr);
  fetched.resize(std::size_t(1 + C) * W);
  float* zc = fetched.data();
  if (history) {
    history_row(f, s.prev, Y, h);
    float* dst[16];
    for (int c = 0; c < C; ++c) dst[c] = fetched.data() + std::size_t(1 + c) * W;
    reproject::gather_row(h, prev_planes.data(), dst, C, W);
    listing72_depth_row(h, s.prev.z.data(), f.mx + row, f.my + row, Y, W, zc);
  } else {
    h.resize(W);
    std::fill(h.hit.begin(), h.hit.end(), 0.0f);
  }
  const bool row_computed = f.rows.d[Y] == 0;
  const std::size_t lrow = std::size_t(f.rows.i0[Y]) * f.lw;
  std::size_t holes = 0, hits = 0;
  for (int X = 0; X < W; ++X) {
    float conf = 1.0f;
    if (row_computed && f.cols.d[X] == 0 && f.lvalid[lrow + f.cols.i0[X]] > 0) {
      for (int c = 0; c < C; ++c) rows[c][X] = f.low[c][lrow + f.cols.i0[X]];
    } else {
      conf = cache_confidence(h.hit[X], f.z[row + X], zc[X], o.miss_threshold, o.convergence_time);
      for (int c = 0; c < C; ++c)
        if (conf > 0) rows[c][X] += (fetched[std::size_t(1 + c) * W + X] - rows[c][X]) * conf;
      hits += conf > 0 ? 1 : 0;
      holes += conf > 0 ? 0 : 1;
    }
    if (dbg_disocc) {
      dbg_disocc[row + X] = conf > 0 ? 0.0f : 1.0f;
      dbg_conv[row + X] = conf;
    }
  }
  return {holes, hits};
}

Image& run_refresh(DrobotState& s, const FrameContext& f, bool have_history, FrameStats& stats) {
  const int C = f.C;
  Image& out = s.out.next();
  const std::vector<float*> planes = payload_planes(out, s.g.channels);
  const std::vector<const float*> prev_planes = payload_planes(s.out.previous(), s.g.channels);
  const bool history = have_history && s.prev.z.size() == std::size_t(f.W) * f.H;
  float* dbg_conf = f.debug ? out.add_channel("debug.confidence") : nullptr;
  float* dbg_disocc = f.debug ? out.add_channel("debug.disocclusion") : nullptr;
  float* dbg_conv = f.debug ? out.add_channel("debug.convergence") : nullptr;
  std::atomic<std::size_t> holes{0}, hits{0};
  parallel_rows(f.H, [&](int y0, int y1) {
    thread_local HistoryRow h;
    thread_local std::vector<float> fetched;
    std::vector<float*> rows(C);
    std::size_t band_holes = 0, band_hits = 0;
    for (int Y = y0; Y < y1; ++Y) {
      for (int c = 0; c < C; ++c) rows[c] = planes[c] + std::size_t(Y) * f.W;
      const auto [ho, hi] =
          refresh_row(s, f, history, Y, rows.data(), prev_planes, h, fetched, dbg_conf, dbg_disocc, dbg_conv);
      band_holes += ho;
      band_hits += hi;
    }
    holes += band_holes;
    hits += band_hits;
  });
  stats.hole_pixels = holes;
  stats.history_pixels = hits;
  s.prev.store(f);
  return out;
}

DrobotState::DrobotState(const Options& o, const Geometry& geometry)
    : opt(drobot_options(o)), out(geometry), g(geometry) {}

Image& DrobotState::run(const FrameContext& f, bool history, FrameStats& stats) {
  if (bilinear_table.size() != std::size_t(f.grid.k) * f.grid.k * 4) bilinear_table = drobot_bilinear_table(f.grid.k);
  return opt.refresh() ? run_refresh(*this, f, history, stats) : run_cache(*this, f, history, stats);
}

// Cache mode: the low-resolution cache (values, depth, frame count) of the last frame; refresh mode: the output
// (the history) and the depth.
void DrobotState::save(Image& state) const {
  if (opt.refresh()) {
    for (const auto& c : g.channels) put_plane(state, "history." + c, out.current().plane(c), g.W, g.H);
    put_previous(state, prev, g.W, g.H);
    return;
  }
  const int cur = out.index();
  for (std::size_t c = 0; c < g.channels.size(); ++c)
    put_plane(state, "cache." + g.channels[c], hb_val[cur][c].data(), g.lw, g.lh);
  put_plane(state, "cache.depth", hb_z[cur].data(), g.lw, g.lh);
  put_plane(state, "cache.frames", hb_n[cur].data(), g.lw, g.lh);
  if (!hb_id[cur].empty()) put_uint_plane(state, "cache.id", hb_id[cur].data(), g.lw, g.lh);
}

Status DrobotState::load(const Image& state) {
  Image& img = out.next();  // the next run() reads it (or the cache of this slot) as the previous frame's
  if (opt.refresh()) {
    for (const auto& c : g.channels)
      if (Status s = get_plane(state, "history." + c, img.plane(c), g.W, g.H); !s) return s;
    return get_previous(state, prev, g.W, g.H);
  }
  const int cur = out.index();
  const std::size_t LN = std::size_t(g.lw) * g.lh;
  hb_val[cur].resize(g.channels.size());
  for (std::size_t c = 0; c < g.channels.size(); ++c) {
    hb_val[cur][c].resize(LN);
    if (Status s = get_plane(state, "cache." + g.channels[c], hb_val[cur][c].data(), g.lw, g.lh); !s) return s;
  }
  hb_z[cur].resize(LN);
  hb_n[cur].resize(LN);
  if (Status s = get_plane(state, "cache.depth", hb_z[cur].data(), g.lw, g.lh); !s) return s;
  if (Status s = get_plane(state, "cache.frames", hb_n[cur].data(), g.lw, g.lh); !s) return s;
  hb_id[cur].clear();
  if (!state.uint_plane("cache.id")) return Status::ok();
  hb_id[cur].resize(LN);
  return get_uint_plane(state, "cache.id", hb_id[cur].data(), g.lw, g.lh);
}

// The history fetch's disocclusion test compares material ids unless --no-ids.
std::size_t streamed_bytes(const Options& o, int W, int H, int k, int C) {
  const std::size_t full = std::size_t(W) * H * 4, low = full / (std::size_t(k) * k);
  std::size_t b = 4 * full + C * low + C * full;  // depth + N, payload in, payload out
  if (drobot_options(o).refresh())
    b += 2 * full + full + 2 * (2 * full) + C * full;  // motion, id; previous depth and id read and written; history
  else
    b += 3 * low + 2 * (C + 3) * low;  // motion and id at the blocks; low-res cache (values, depth, count, id) r+w
  return b;
}

// The state holds either the low-resolution cache or the full-resolution history.
std::string state_layout(const Options& o) { return "mode " + drobot_options(o).mode; }

}  // namespace

const MethodEntry& drobot_method() {
  static const MethodEntry entry{
      .info = {.name = "drobot",
               .summary = "spatiotemporal coherence framework (seed 002, Listings 7.1-7.3): low-resolution "
                          "reprojection cache with convergence, bilateral filter, bilateral upsampling",
               .has_state = true,
               .variants = {{"drobot-refresh", "drobot", {"--mode", "refresh"},
                             "the refresh-buffer reconstruction of Figure 7.12"}}},
      .make_options = OptionsOf<DrobotOptions>::make,
      .layers = history_method_layers,
      .implementations = {{kCpuDevice,
                           [](const Options& o, const Geometry& g) -> std::unique_ptr<MethodState> {
                             return std::make_unique<DrobotState>(o, g);
                           }},
                          // drobot_gpu.cpp: both modes as GLSL kernels, the same state planes.
                          {kGpuDevice, gpu_implementation<make_drobot_state_gpu>}},
      .streamed_bytes = streamed_bytes,
      .state_layout = state_layout,
      .header_name = [](const Options& o) { return "drobot-" + drobot_options(o).mode; }};
  return entry;
}

}  // namespace temporal::upsample
