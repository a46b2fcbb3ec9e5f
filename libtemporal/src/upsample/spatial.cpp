// `spatial`: joint-bilateral upsampling, seed 000 section 3.1 (eq. 1-3) with the hat image kernel of
// [Yang et al. 2008]. Whole frames read the two low rows of each full row expanded to full-resolution columns
// (ExpandedLowRows, shared with herzog's pass A): unit-stride loads instead of ~32 gathers per pixel. The
// gathering version (spatial_row, in upsampler.cpp) serves `temporal`'s sparse hole runs; both compute the
// same weights in the same order, so their results are bit-identical.
#include "upsample_internal.h"

#include "temporal/parallel.h"

namespace temporal::upsample {
namespace {

// Eq. 1-3 for full row Y from the expanded low rows e0 (row i0) and e1 (row i1), plane stride es: out[c] and
// (when not null) the sum of weights.
void spatial_row_expanded(const Upsampler::State& s, const FrameContext& f, const Options& o, int Y, const float* e0,
                          const float* e1, std::size_t es, float* const* out, float* wsum, float* w4) {
  const int W = f.W, k = f.grid.k;
  float* __restrict w00 = w4;
  float* __restrict w01 = w00 + W;
  float* __restrict w10 = w01 + W;
  float* __restrict w11 = w10 + W;
  const float vy0 = s.rows.v0[Y], vy1 = s.rows.v1[Y];
  const float fy = float(s.rows.d[Y]) / float(k), inv_k = 1.0f / float(k);
  const float inv_sn2 = 1.0f / (o.sigma_normal * o.sigma_normal), inv_sd2 = 1.0f / (f.sigma_d * f.sigma_d);
  const std::size_t row = std::size_t(Y) * W;
  const float* __restrict z = f.z + row;
  const float* __restrict nx = f.nx + row;
  const float* __restrict ny = f.ny + row;
  const float* __restrict nz = f.nz + row;
  const int* __restrict cd = s.cols.d.data();
  const float* __restrict cv0 = s.cols.v0.data();
  const float* __restrict cv1 = s.cols.v1.data();
  // Plane q, tap t (0: column i0, 1: column i1 = the i0 expansion shifted by k) of an expanded low row.
  auto ex = [es, k](const float* e, int q, int t) { return e + std::size_t(q) * es + std::size_t(t) * k; };
  const float *__restrict z00 = ex(e0, 0, 0), *__restrict z01 = ex(e0, 0, 1), *__restrict z10 = ex(e1, 0, 0),
              *__restrict z11 = ex(e1, 0, 1);
  const float *__restrict x00 = ex(e0, 1, 0), *__restrict x01 = ex(e0, 1, 1), *__restrict x10 = ex(e1, 1, 0),
              *__restrict x11 = ex(e1, 1, 1);
  const float *__restrict y00 = ex(e0, 2, 0), *__restrict y01 = ex(e0, 2, 1), *__restrict y10 = ex(e1, 2, 0),
              *__restrict y11 = ex(e1, 2, 1);
  const float *__restrict n00 = ex(e0, 3, 0), *__restrict n01 = ex(e0, 3, 1), *__restrict n10 = ex(e1, 3, 0),
              *__restrict n11 = ex(e1, 3, 1);
  const float *__restrict v00 = ex(e0, 4, 0), *__restrict v01 = ex(e0, 4, 1), *__restrict v10 = ex(e1, 4, 0),
              *__restrict v11 = ex(e1, 4, 1);
  // Normal and depth tri-weight tents (eq. 2-3), cubed, of one low-resolution sample; as in spatial_row.
  auto geo = [=](float zi, float ax, float ay, float az, float lx, float ly, float lzn, float lzz, float lv) {
    const float dot = ax * lx + ay * ly + az * lzn;
    const float xn = std::max(0.0f, 1.0f - dot);
    const float tn = std::max(kKernelEpsilon, 1.0f - xn * xn * inv_sn2);
    const float dz = zi - lzz;
    const float td = std::max(kKernelEpsilon, 1.0f - dz * dz * inv_sd2);
    const float w = tn * tn * tn * td * td * td * lv;
    return w >= 0.0f ? w : 0.0f;  // NaN geometry at the pixel gives no weight
  };
#pragma GCC ivdep
  for (int X = 0; X < W; ++X) {
    const float fx = float(cd[X]) * inv_k;
    const float zi = z[X], ax = nx[X], ay = ny[X], az = nz[X];
    w00[X] = geo(zi, ax, ay, az, x00[X], y00[X], n00[X], z00[X], v00[X]) * (1 - fx) * (1 - fy) * cv0[X] * vy0;
    w01[X] = geo(zi, ax, ay, az, x01[X], y01[X], n01[X], z01[X], v01[X]) * fx * (1 - fy) * cv1[X] * vy0;
    w10[X] = geo(zi, ax, ay, az, x10[X], y10[X], n10[X], z10[X], v10[X]) * (1 - fx) * fy * cv0[X] * vy1;
    w11[X] = geo(zi, ax, ay, az, x11[X], y11[X], n11[X], z11[X], v11[X]) * fx * fy * cv1[X] * vy1;
  }
  for (int c = 0; c < f.C; ++c) {
    const float* __restrict l00 = ex(e0, 5 + c, 0);
    const float* __restrict l01 = ex(e0, 5 + c, 1);
    const float* __restrict l10 = ex(e1, 5 + c, 0);
    const float* __restrict l11 = ex(e1, 5 + c, 1);
    float* __restrict o_ = out[c];
#pragma GCC ivdep
    for (int X = 0; X < W; ++X) {
      const float ws = w00[X] + w01[X] + w10[X] + w11[X];
      // Invalid samples carry weight 0 and their value (possibly NaN) is replaced by 0.
      const float la = l00[X], lb = l01[X], lc = l10[X], ld = l11[X];
      const float a = w00[X] > 0 ? la : 0.0f, b = w01[X] > 0 ? lb : 0.0f;
      const float cc = w10[X] > 0 ? lc : 0.0f, d = w11[X] > 0 ? ld : 0.0f;
      const float v = w00[X] * a + w01[X] * b + w10[X] * cc + w11[X] * d;
      o_[X] = ws > 0 ? v / ws : 0.0f;
    }
  }
  if (wsum)
    for (int X = 0; X < W; ++X) wsum[X] = w00[X] + w01[X] + w10[X] + w11[X];
}

}  // namespace

void run_spatial(Upsampler::State& s, const FrameContext& f, const Options& o, FrameStats& stats) {
  Image& out = s.result[s.cur];
  std::vector<float*> planes;
  for (const auto& c : s.channels) planes.push_back(out.plane(c));
  float* conf = o.debug_layers ? out.add_channel("debug.confidence") : nullptr;
  // Bands of 16 rows: the k rows that share a pair of low rows reuse their expansion.
  parallel_rows(f.H, [&](int y0, int y1) {
    thread_local ExpandedLowRows low_rows;
    thread_local std::vector<float> w4;
    low_rows.reset(f.W, f.grid.k, f.grid.sx, f.C);
    w4.resize(std::size_t(f.W) * 4);
    float* rows[16];
    for (int Y = y0; Y < y1; ++Y) {
      const std::size_t off = std::size_t(Y) * f.W;
      for (std::size_t c = 0; c < planes.size(); ++c) rows[c] = planes[c] + off;
      const float *e0 = nullptr, *e1 = nullptr;
      low_rows.get(s, f, s.rows.i0[Y] * f.lw, s.rows.i1[Y] * f.lw, e0, e1);
      spatial_row_expanded(s, f, o, Y, e0, e1, low_rows.stride(), rows, conf ? conf + off : nullptr, w4.data());
    }
  }, 16);
  stats.hole_pixels = 0;
  stats.history_pixels = 0;
}

}  // namespace temporal::upsample
