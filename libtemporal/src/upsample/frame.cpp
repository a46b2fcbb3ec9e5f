// The per-frame pieces every upsampling method shares: tap tables of the jittered grid, the geometry of this
// frame's samples, the joint-bilateral row kernel (seed 000 eq. 1-3), the previous frame's geometry, output images
// and state planes, and the payload's channel selection.
#include "method.h"

#include "temporal/core/parallel.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace temporal::upsample {

namespace {
// The methods' non-temporal row copy (stream_row.inc), compiled here for the baseline: 16-byte streaming stores.
constexpr int kCopyVectorFloats = 4;
#include "stream_row.inc"
}  // namespace

std::string join_names(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& x : names) s += (s.empty() ? "" : ", ") + x;
  return s.empty() ? "(none)" : s;
}

Expected<std::vector<std::string>> select_channels(const Image& low, const std::string& layers, const std::string& file) {
  return select_layers(low, layers, file);  // the --layer rule of every tool (temporal/core/image.h)
}

bool TapTable::build(int full, int low, int k, int s) {
  if (key_[0] == full && key_[1] == low && key_[2] == k && key_[3] == s) return false;
  key_[0] = full;
  key_[1] = low;
  key_[2] = k;
  key_[3] = s;
  i0.resize(full);
  i1.resize(full);
  d.resize(full);
  v0.resize(full);
  v1.resize(full);
  for (int X = 0; X < full; ++X) {
    const int x0 = JitterGrid::floor_div(X - s, k);
    d[X] = X - s - k * x0;
    v0[X] = (x0 >= 0 && x0 < low) ? 1.0f : 0.0f;
    v1[X] = (x0 + 1 >= 0 && x0 + 1 < low) ? 1.0f : 0.0f;
    i0[X] = std::clamp(x0, 0, low - 1);
    i1[X] = std::clamp(x0 + 1, 0, low - 1);
  }
  return true;
}

namespace {
#include "low_geometry_row.inc"
}  // namespace

void gather_low_geometry(FrameContext& f) {
  const std::size_t n = std::size_t(f.lw) * f.lh;
  f.lz.resize(n);
  f.lnx.resize(n);
  f.lny.resize(n);
  f.lnz.resize(n);
  f.lvalid.resize(n);
  parallel_rows(f.lh, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
      const std::size_t i = std::size_t(y) * f.lw;
      low_geometry_row(f, y, f.lz.data() + i, f.lnx.data() + i, f.lny.data() + i, f.lnz.data() + i,
                       f.lvalid.data() + i);
    }
  });
}

void clear_low_geometry(FrameContext& f) {
  for (auto* v : {&f.lz, &f.lnx, &f.lny, &f.lnz, &f.lvalid}) v->clear();
}

void spatial_row(const FrameContext& f, int Y, float* const* out, float* wsum, int X0, int X1) {
  const Options& o = *f.options;
  // Four weights per pixel are computed into thread-local rows first (a loop that vectorises, with gathers),
  // then each channel is accumulated in its own unit-stride loop. Restrict-qualified locals let the
  // compiler vectorise without alias checks.
  thread_local std::vector<float> w4;
  w4.resize(std::size_t(f.W) * 4);
  float* __restrict w00 = w4.data();
  float* __restrict w01 = w00 + f.W;
  float* __restrict w10 = w01 + f.W;
  float* __restrict w11 = w10 + f.W;
  const int W = f.W, k = f.grid.k;
  if (X1 < 0) X1 = W;
  const int r0 = f.rows.i0[Y] * f.lw, r1 = f.rows.i1[Y] * f.lw;
  const float vy0 = f.rows.v0[Y], vy1 = f.rows.v1[Y];
  const float fy = float(f.rows.d[Y]) / float(k), inv_k = 1.0f / float(k);
  const float inv_sn2 = 1.0f / (o.sigma_normal * o.sigma_normal), inv_sd2 = 1.0f / (f.sigma_d * f.sigma_d);
  const std::size_t row = std::size_t(Y) * W;
  const float* __restrict z = f.z + row;
  const float* __restrict nx = f.nx + row;
  const float* __restrict ny = f.ny + row;
  const float* __restrict nz = f.nz + row;
  const int* __restrict ci0 = f.cols.i0.data();
  const int* __restrict ci1 = f.cols.i1.data();
  const int* __restrict cd = f.cols.d.data();
  const float* __restrict cv0 = f.cols.v0.data();
  const float* __restrict cv1 = f.cols.v1.data();
  const float* __restrict lz = f.lz.data();
  const float* __restrict lnx = f.lnx.data();
  const float* __restrict lny = f.lny.data();
  const float* __restrict lnz = f.lnz.data();
  const float* __restrict lvalid = f.lvalid.data();
  // Geometric weights (eq. 2-3, shared with the expanded-row kernels: same operations in the same order, so
  // the same bits) times tap existence, then the hat image kernel.
  auto geo = [=](int j, float zi, float ax, float ay, float az) {
    return sample_weight(zi, ax, ay, az, lnx[j], lny[j], lnz[j], lz[j], lvalid[j], inv_sn2, inv_sd2);
  };
#pragma GCC ivdep
  for (int X = X0; X < X1; ++X) {
    const float fx = float(cd[X]) * inv_k;
    const float zi = z[X], ax = nx[X], ay = ny[X], az = nz[X];
    w00[X] = geo(r0 + ci0[X], zi, ax, ay, az) * cv0[X] * vy0 * (1 - fx) * (1 - fy);
    w01[X] = geo(r0 + ci1[X], zi, ax, ay, az) * cv1[X] * vy0 * fx * (1 - fy);
    w10[X] = geo(r1 + ci0[X], zi, ax, ay, az) * cv0[X] * vy1 * (1 - fx) * fy;
    w11[X] = geo(r1 + ci1[X], zi, ax, ay, az) * cv1[X] * vy1 * fx * fy;
  }
  for (int c = 0; c < f.C; ++c) {
    const float* __restrict l0 = f.low[c] + r0;
    const float* __restrict l1 = f.low[c] + r1;
    float* __restrict o_ = out[c];
#pragma GCC ivdep
    for (int X = X0; X < X1; ++X) {
      const float ws = w00[X] + w01[X] + w10[X] + w11[X];
      // Invalid samples carry weight 0, and their value is replaced by 0 so that a NaN never propagates.
      // Unconditional loads (clamped indices, always valid) and a select: conditional loads would need
      // masked gathers, which keep the loop scalar.
      const float la = l0[ci0[X]], lb = l0[ci1[X]], lc = l1[ci0[X]], ld = l1[ci1[X]];
      const float a = w00[X] > 0 ? la : 0.0f, b = w01[X] > 0 ? lb : 0.0f;
      const float cc = w10[X] > 0 ? lc : 0.0f, d = w11[X] > 0 ? ld : 0.0f;
      const float v = w00[X] * a + w01[X] * b + w10[X] * cc + w11[X] * d;
      o_[X] = ws > 0 ? v / ws : 0.0f;
    }
  }
  if (wsum)
    for (int X = X0; X < X1; ++X) wsum[X] = w00[X] + w01[X] + w10[X] + w11[X];
}

// A copy of 8 bytes per pixel (10 MB at 1280x1024) that every history method makes once per frame: in parallel
// chunks, not a serial assign (which kept one of two cores idle for about 1 ms of taau's ~27 ms frame).
void PreviousGeometry::store(const FrameContext& f) {
  const std::size_t n = std::size_t(f.W) * f.H;
  z.resize(n);
  if (f.id)
    id.resize(n);
  else
    id.clear();
  // Non-temporal stores (stream_row): the next frame reads these planes, this one does not. memcpy's chunks of 64 KiB
  // are below glibc's non-temporal threshold, so they stored through the cache and read every line of the two
  // planes from memory first (write-allocate, 10.5 MB per frame at 1280x1024). Frames of the two versions
  // interleaved in one process (issue 27, 2026-11-30): temporal 3-4 % faster on two threads and on one,
  // drobot-refresh 1-3 % (docs/history/upsample-st-speed.md, "ninth session"). The same bytes.
  parallel_chunks(n, [&](std::size_t b, std::size_t e) {
    stream_row(z.data() + b, f.z + b, int(e - b));
    if (f.id) stream_row(id.data() + b, f.id + b, int(e - b));
#if defined(__SSE2__)
    _mm_sfence();  // this task's streamed stores are visible before the join hands the planes on
#endif
  }, std::size_t(1) << 14);
}

OutputPair::OutputPair(const Geometry& g) {
  for (auto& img : img_) {
    img = Image(g.W, g.H);
    for (const auto& c : g.channels) img.add_channel(c);
  }
}

std::vector<float*> payload_planes(Image& img, const std::vector<std::string>& channels) {
  std::vector<float*> planes;
  for (const auto& c : channels) planes.push_back(img.plane(c));
  return planes;
}
std::vector<const float*> payload_planes(const Image& img, const std::vector<std::string>& channels) {
  std::vector<const float*> planes;
  for (const auto& c : channels) planes.push_back(img.plane(c));
  return planes;
}

// --- State planes ---------------------------------------------------------------------------------------------

namespace {
template <typename T>
void copy_in(T* dst, const T* src, int w, int h, int stride) {
  for (int y = 0; y < h; ++y) std::copy_n(src + std::size_t(y) * w, w, dst + std::size_t(y) * stride);
}
template <typename T>
void copy_out(T* dst, const T* src, int w, int h, int stride) {
  for (int y = 0; y < h; ++y) std::copy_n(src + std::size_t(y) * stride, w, dst + std::size_t(y) * w);
}
Error missing(const Image& state, const std::string& name) {
  return Error::input({}, "the state has no channel '" + name + "' (have: " + join_names(state.channel_names()) +
                              "); pass a --state-out file of the same method and options");
}
}  // namespace

void put_plane(Image& state, const std::string& name, const float* src, int w, int h) {
  copy_in(state.add_channel(name), src, w, h, state.width());
}
void put_uint_plane(Image& state, const std::string& name, const std::uint32_t* src, int w, int h) {
  copy_in(state.add_uint_channel(name), src, w, h, state.width());
}
Status get_plane(const Image& state, const std::string& name, float* dst, int w, int h, StateValues values) {
  const float* p = state.plane(name);
  if (!p) return missing(state, name);
  copy_out(dst, p, w, h, state.width());
  if (values == StateValues::Finite)
    if (const std::size_t bad = count_non_finite({dst, std::size_t(w) * std::size_t(h)}); bad > 0)
      return Error::input({}, "the state's channel '" + name + "' holds " + std::to_string(bad) +
                                  " values that are not finite (NaN or infinity), which --state-out never writes: "
                                  "the file is damaged; pass an intact --state-out file, or drop --state-in to "
                                  "start without history");
  return Status::ok();
}
Status get_uint_plane(const Image& state, const std::string& name, std::uint32_t* dst, int w, int h) {
  const std::uint32_t* p = state.uint_plane(name);
  if (!p) return missing(state, name);
  copy_out(dst, p, w, h, state.width());
  return Status::ok();
}

void put_previous(Image& state, const PreviousGeometry& prev, int W, int H) {
  put_plane(state, "prev.depth", prev.z.data(), W, H);
  if (!prev.id.empty()) put_uint_plane(state, "prev.id", prev.id.data(), W, H);
}
Status get_previous(const Image& state, PreviousGeometry& prev, int W, int H) {
  prev.z.resize(std::size_t(W) * H);
  if (Status s = get_plane(state, "prev.depth", prev.z.data(), W, H); !s) return s;
  prev.id.clear();
  if (state.uint_plane("prev.id")) {
    prev.id.resize(std::size_t(W) * H);
    return get_uint_plane(state, "prev.id", prev.id.data(), W, H);
  }
  return Status::ok();
}

}  // namespace temporal::upsample
