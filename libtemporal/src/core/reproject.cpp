// The reprojection module (temporal/core/reproject.h): the row kernels every history method and metric uses.
//
// reproject_row works in two steps per row: (1) per pixel, the tap indices, the bilinear weights of the taps and
// the run structure, without touching the previous frame (a loop that vectorises, no gathers); (2) per segment,
// the depth / id tests against the previous frame, with contiguous loads where the taps are aligned (most of a
// typical frame) and gathers elsewhere. Same values as testing everything in one gathered loop.
#include "temporal/core/reproject.h"

#include "temporal/core/parallel.h"

#include <limits>

namespace temporal::reproject {

void HistoryRow::resize(int W) {
  for (auto& v : q) v.resize(W);
  for (auto& v : w) v.resize(W);
  hit.resize(W);
  offset.resize(W);
  aligned.resize(W);
}

void build_segments(HistoryRow& h, int W) {
  h.segments.clear();
  const int* __restrict off = h.offset.data();
  const int* __restrict al = h.aligned.data();
  int gather_start = -1, X = 0;
  while (X < W) {
    const int base = off[X];
    int E = X;
    if (al[X]) {
      while (E + 16 <= W) {  // whole blocks first (a reduction the compiler vectorises)
        int all = 1;
        for (int i = 0; i < 16; ++i) all &= int(off[E + i] == base) & al[E + i];
        if (!all) break;
        E += 16;
      }
      while (E < W && off[E] == base && al[E]) ++E;
    }
    if (E - X >= 16) {
      if (gather_start >= 0) h.segments.push_back({gather_start, X, -1});
      gather_start = -1;
      h.segments.push_back({X, E, base});
      X = E;
    } else {
      if (gather_start < 0) gather_start = X;
      X = std::max(E, X + 1);
    }
  }
  if (gather_start >= 0) h.segments.push_back({gather_start, W, -1});
}

namespace {

// Depth / id test of the four taps, the renormalised weights and the hit flag for pixels [X0, X1). w holds the
// bilinear weights already zeroed for taps outside the image; kAligned: the taps are base + X (+1, +W, +W+1),
// loaded contiguously; otherwise gathered through q. Branch-free (bitwise & of the tests) so that it vectorises.
template <bool kDepth, bool kIds, bool kAligned>
void test_taps(const float* __restrict zr, const std::uint32_t* __restrict idr, const float* __restrict pz,
               const std::uint32_t* __restrict pid, float tol, int W, int X0, int X1, int base, HistoryRow& h) {
  const int* __restrict q0 = h.q[0].data();
  const int* __restrict q1 = h.q[1].data();
  const int* __restrict q2 = h.q[2].data();
  const int* __restrict q3 = h.q[3].data();
  float* __restrict w0 = h.w[0].data();
  float* __restrict w1 = h.w[1].data();
  float* __restrict w2 = h.w[2].data();
  float* __restrict w3 = h.w[3].data();
  float* __restrict hit = h.hit.data();
  // same_surface() of the header, written out for the vectoriser (z > zp ? z : zp is fmax for non-NaN depths).
  auto same = [=](float z, float zp) { return std::abs(z - zp) <= tol * (z > zp ? z : zp); };
#pragma GCC ivdep
  for (int X = X0; X < X1; ++X) {
    const int a = kAligned ? base + X : q0[X], b = kAligned ? base + X + 1 : q1[X];
    const int c = kAligned ? base + X + W : q2[X], d = kAligned ? base + X + W + 1 : q3[X];
    bool ok0 = true, ok1 = true, ok2 = true, ok3 = true;
    if constexpr (kDepth) {
      const float z = zr[X];
      ok0 = same(z, pz[a]);
      ok1 = same(z, pz[b]);
      ok2 = same(z, pz[c]);
      ok3 = same(z, pz[d]);
    }
    if constexpr (kIds) {
      const std::uint32_t id = idr[X];
      ok0 = ok0 & (pid[a] == id);
      ok1 = ok1 & (pid[b] == id);
      ok2 = ok2 & (pid[c] == id);
      ok3 = ok3 & (pid[d] == id);
    }
    const float e0 = ok0 ? w0[X] : 0.0f, e1 = ok1 ? w1[X] : 0.0f;
    const float e2 = ok2 ? w2[X] : 0.0f, e3 = ok3 ? w3[X] : 0.0f;
    const float sum = e0 + e1 + e2 + e3;
    const float inv = sum >= kMinHitWeight ? 1.0f / sum : 0.0f;
    w0[X] = e0 * inv;
    w1[X] = e1 * inv;
    w2[X] = e2 * inv;
    w3[X] = e3 * inv;
    hit[X] = inv > 0.0f ? 1.0f : 0.0f;
  }
}

template <bool kDepth, bool kIds>
void reproject_row_impl(const Frames& fr, int Y, HistoryRow& h) {
  const int W = fr.width, H = fr.height;
  const std::size_t row = std::size_t(Y) * W;
  // No motion: a row of zeros, so that the loop below loads unconditionally (it vectorises).
  thread_local std::vector<float> zeros;
  const bool moving = fr.motion_x && fr.motion_y;
  if (!moving && zeros.size() < std::size_t(W)) zeros.assign(std::size_t(W), 0.0f);
  const float* __restrict mxr = moving ? fr.motion_x + row : zeros.data();
  const float* __restrict myr = moving ? fr.motion_y + row : zeros.data();
  int* __restrict q0 = h.q[0].data();
  int* __restrict q1 = h.q[1].data();
  int* __restrict q2 = h.q[2].data();
  int* __restrict q3 = h.q[3].data();
  float* __restrict w0 = h.w[0].data();
  float* __restrict w1 = h.w[1].data();
  float* __restrict w2 = h.w[2].data();
  float* __restrict w3 = h.w[3].data();
  int* __restrict off = h.offset.data();
  int* __restrict al = h.aligned.data();
  const float fY = float(Y), fW = float(W), fH = float(H);
  // Bitwise & instead of && keeps the loop free of branches (it vectorises).
#pragma GCC ivdep
  for (int X = 0; X < W; ++X) {
    float mx = mxr[X], my = myr[X];
    const bool finite = (std::abs(mx) < 1e6f) & (std::abs(my) < 1e6f);  // NaN/Inf/absurd motion: no history
    mx = finite ? mx : 0.0f;
    my = finite ? my : 0.0f;
    const float u = float(X) + mx, v = fY + my;
    const bool ok = finite & (u >= -0.5f) & (v >= -0.5f) & (u < fW - 0.5f) & (v < fH - 0.5f);  // on_screen()
    const float fu = floor_vec(u), fv = floor_vec(v);  // |u|, |v| < 1e6 + size
    const float ax = u - fu, ay = v - fv;
    const int x0 = int(fu), y0 = int(fv);
    const bool ix0 = (x0 >= 0) & (x0 < W), ix1 = (x0 + 1 >= 0) & (x0 + 1 < W);
    const bool iy0 = (y0 >= 0) & (y0 < H), iy1 = (y0 + 1 >= 0) & (y0 + 1 < H);
    const int cx0 = std::clamp(x0, 0, W - 1), cx1 = std::clamp(x0 + 1, 0, W - 1);
    const int cy0 = std::clamp(y0, 0, H - 1), cy1 = std::clamp(y0 + 1, 0, H - 1);
    const int a = cy0 * W + cx0, b = cy0 * W + cx1, c = cy1 * W + cx0, d = cy1 * W + cx1;
    q0[X] = a;
    q1[X] = b;
    q2[X] = c;
    q3[X] = d;
    w0[X] = (ok & ix0 & iy0) ? (1 - ax) * (1 - ay) : 0.0f;
    w1[X] = (ok & ix1 & iy0) ? ax * (1 - ay) : 0.0f;
    w2[X] = (ok & ix0 & iy1) ? (1 - ax) * ay : 0.0f;
    w3[X] = (ok & ix1 & iy1) ? ax * ay : 0.0f;
    off[X] = a - X;
    al[X] = int(b == a + 1) & int(c == a + W) & int(d == c + 1);
  }
  build_segments(h, W);
  const float* zr = kDepth ? fr.z + row : nullptr;
  const std::uint32_t* idr = kIds ? fr.id + row : nullptr;
  const float tol = fr.test.depth_tolerance;
  for (const auto& sg : h.segments) {
    if (sg.base >= 0)
      test_taps<kDepth, kIds, true>(zr, idr, fr.prev_z, fr.prev_id, tol, W, sg.x0, sg.x1, sg.base, h);
    else
      test_taps<kDepth, kIds, false>(zr, idr, fr.prev_z, fr.prev_id, tol, W, sg.x0, sg.x1, 0, h);
  }
}

// The image-aligned four-tap gather (taps base + X, + 1, + W, + W + 1) of N = 3 or 4 planes in one loop: the
// weights are loaded once for all planes. Same expression per plane as the loops of gather_group.
template <int N>
void gather_aligned(const float* const* prev, float* const* out, const float* __restrict w0,
                    const float* __restrict w1, const float* __restrict w2, const float* __restrict w3, int X0, int X1,
                    int base, int W) {
  static_assert(N == 3 || N == 4);
  const float* __restrict pa = prev[0];
  const float* __restrict pb = prev[1];
  const float* __restrict pc = prev[2];
  const float* __restrict pd = prev[N - 1];
  float* __restrict oa = out[0];
  float* __restrict ob = out[1];
  float* __restrict oc = out[2];
  float* __restrict od = out[N - 1];
#pragma GCC ivdep
  for (int X = X0; X < X1; ++X) {
    const int a = base + X;
    const float a0 = w0[X], a1 = w1[X], a2 = w2[X], a3 = w3[X];
    oa[X] = a0 * pa[a] + a1 * pa[a + 1] + a2 * pa[a + W] + a3 * pa[a + W + 1];
    ob[X] = a0 * pb[a] + a1 * pb[a + 1] + a2 * pb[a + W] + a3 * pb[a + W + 1];
    oc[X] = a0 * pc[a] + a1 * pc[a + 1] + a2 * pc[a + W] + a3 * pc[a + W + 1];
    if constexpr (N == 4) od[X] = a0 * pd[a] + a1 * pd[a + 1] + a2 * pd[a + W] + a3 * pd[a + W + 1];
  }
}

// Up to 4 planes in one pass over the segments (indices and weights loaded once for all planes).
void gather_group(const HistoryRow& h, const float* const* prev, float* const* out, int n, int W) {
  const int* __restrict q0 = h.q[0].data();
  const int* __restrict q1 = h.q[1].data();
  const int* __restrict q2 = h.q[2].data();
  const int* __restrict q3 = h.q[3].data();
  const float* __restrict w0 = h.w[0].data();
  const float* __restrict w1 = h.w[1].data();
  const float* __restrict w2 = h.w[2].data();
  const float* __restrict w3 = h.w[3].data();
  for (const auto& sg : h.segments) {
    const int X0 = sg.x0, X1 = sg.x1, base = sg.base;
    const bool contiguous = base >= 0;
    if (contiguous && n == 4) {
      gather_aligned<4>(prev, out, w0, w1, w2, w3, X0, X1, base, W);
      continue;
    }
    if (contiguous && n == 3) {
      gather_aligned<3>(prev, out, w0, w1, w2, w3, X0, X1, base, W);
      continue;
    }
    for (int i = 0; i < n; ++i) {
      const float* __restrict p = prev[i];
      float* __restrict o = out[i];
      if (contiguous) {
        // Taps 0/1 are p[base + X], p[base + X + 1]; taps 2/3 the same one row below.
#pragma GCC ivdep
        for (int X = X0; X < X1; ++X) {
          const int a = base + X;
          o[X] = w0[X] * p[a] + w1[X] * p[a + 1] + w2[X] * p[a + W] + w3[X] * p[a + W + 1];
        }
      } else {
#pragma GCC ivdep
        for (int X = X0; X < X1; ++X)
          o[X] = w0[X] * p[q0[X]] + w1[X] * p[q1[X]] + w2[X] * p[q2[X]] + w3[X] * p[q3[X]];
      }
    }
  }
}

}  // namespace

void reproject_row(const Frames& frames, int y, HistoryRow& h) {
  h.resize(frames.width);
  const bool depth = frames.z && frames.prev_z;
  const bool ids = frames.test.use_ids && frames.id && frames.prev_id;
  if (depth && ids)
    reproject_row_impl<true, true>(frames, y, h);
  else if (depth)
    reproject_row_impl<true, false>(frames, y, h);
  else if (ids)
    reproject_row_impl<false, true>(frames, y, h);
  else
    reproject_row_impl<false, false>(frames, y, h);
}

void gather_row(const HistoryRow& h, const float* const* prev, float* const* out, int n, int width) {
  for (int i = 0; i < n; i += 4) gather_group(h, prev + i, out + i, std::min(4, n - i), width);
}

void warp_planes(const Frames& frames, std::span<const float* const> previous, std::span<float* const> out) {
  const int W = frames.width;
  const std::size_t planes = std::min(previous.size(), out.size());
  const float nan = std::numeric_limits<float>::quiet_NaN();
  parallel_rows(frames.height, [&](int y0, int y1) {
    thread_local HistoryRow h;
    thread_local std::vector<float*> rows;
    rows.resize(planes);
    for (int y = y0; y < y1; ++y) {
      const std::size_t row = std::size_t(y) * W;
      reproject_row(frames, y, h);
      for (std::size_t k = 0; k < planes; ++k) rows[k] = out[k] + row;
      gather_row(h, previous.data(), rows.data(), int(planes), W);
      const float* __restrict hit = h.hit.data();
      for (std::size_t k = 0; k < planes; ++k) {
        float* __restrict o = rows[k];
        for (int x = 0; x < W; ++x) o[x] = hit[x] > 0.0f ? o[x] : nan;
      }
    }
  });
}

}  // namespace temporal::reproject
