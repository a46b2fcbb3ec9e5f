// The per-frame context and the kernels shared by the upsampling methods (not installed).
#pragma once

#include "temporal/core/image.h"
#include "temporal/core/reproject.h"
#include "temporal/upsample/joint_bilateral.h"
#include "temporal/upsample/upsample.h"

#include <bit>
#include <cmath>
#include <cstdint>
#include <vector>

namespace temporal::upsample {

// Vectorisable exp2 / log2 for the per-tap kernel powers (std::pow does not vectorise without
// -ffast-math). log2: relative error < 1e-6 on normal positive floats; exp2: relative error < 2e-6 for
// x in [-126, 0], clamped below.
inline float fast_log2(float x) {
  const std::uint32_t bits = std::bit_cast<std::uint32_t>(x);
  const float e = float(int((bits >> 23) & 255u) - 127);
  const float m = std::bit_cast<float>((bits & 0x7fffffu) | 0x3f800000u);  // [1, 2)
  const float t = (m - 1.0f) / (m + 1.0f);                                 // [0, 1/3)
  const float t2 = t * t;
  const float s = t * (1.0f + t2 * (1.0f / 3 + t2 * (1.0f / 5 + t2 * (1.0f / 7 + t2 * (1.0f / 9)))));
  return e + s * 2.8853900817779268f;  // 2 / ln 2
}
inline float fast_exp2(float x) {
  // Clamp to [-126, 0] on the bits: a float select followed by the float->int conversion below makes GCC
  // split the paths, and the loop no longer if-converts (stays scalar). x > 0 -> +0 (sign bit clear: mask 0);
  // for negative x the magnitude orders like the unsigned bits, so min() with the bits of -126 clamps.
  // Same values as min(max(x, -126), 0) for every non-NaN x.
  std::uint32_t u = std::bit_cast<std::uint32_t>(x);
  u &= std::uint32_t(std::int32_t(u) >> 31);
  u = u < 0xC2FC0000u ? u : 0xC2FC0000u;  // bits of -126.0f
  x = std::bit_cast<float>(u);
  const float xi = reproject::floor_vec(x);
  const float f = (x - xi) * 0.69314718056f;  // 2^f = e^(f ln 2)
  const float p =
      1.0f + f * (1.0f + f * (0.5f + f * (1.0f / 6 + f * (1.0f / 24 + f * (1.0f / 120 + f * (1.0f / 720 + f * (1.0f / 5040)))))));
  const float scale = std::bit_cast<float>(std::uint32_t(int(xi) + 127) << 23);
  return p * scale;
}

// Per-column and per-row tap tables of the jittered low-resolution grid: taps x0 = floor((X - sx) / k) and
// x0 + 1, clamped read indices, 0/1 validity (a tap outside the low image does not exist), offset X - (k x0 + sx).
struct TapTable {
  std::vector<int> i0, i1, d;
  std::vector<float> v0, v1;
  // Fills the table for (full, low, k, s); returns false, leaving it as it is, when it already holds that table (a
  // frame's tables repeat: the cache grid's never change, the samples' cycle through the k jitter offsets; four
  // scalar loops with a division per entry, serial at the start of every frame, were ~1 % of drobot's samples).
  bool build(int full, int low, int k, int s);
  // The entries X with d[X] == 0 into `out`: the full-resolution columns (rows) that hold this frame's samples, one
  // in k (temporal and drobot's refresh mode write their samples there after the row's vector loops).
  void sample_entries(std::vector<int>& out) const {
    out.clear();
    for (std::size_t X = 0; X < d.size(); ++X)
      if (d[X] == 0) out.push_back(int(X));
  }

 private:
  int key_[4] = {-1, -1, -1, -1};
};

// Everything one frame needs, resolved and validated by Upsampler::process(), shared by every method: the frame's
// planes, the constants derived from the options and headers, and where this frame's low-resolution samples lie
// (tap tables) with their geometry read from the G-buffer. Owned by the Upsampler and refilled every frame (its
// buffers are reused).
struct FrameContext {
  int W = 0, H = 0;      // full (G-buffer) resolution
  int lw = 0, lh = 0;    // low resolution
  JitterGrid grid;       // k, sx, sy
  int C = 0;             // payload channels
  std::vector<const float*> low;  // C low-resolution planes
  const float *z = nullptr, *nx = nullptr, *ny = nullptr, *nz = nullptr, *mx = nullptr, *my = nullptr;
  const std::uint32_t* id = nullptr;
  const float* prev_z = nullptr;  // prevDepth.Z, the warped depth (seed 000 3.2); null: absent or --no-depth-velocity
  float sigma_d = 1.0f;      // world units
  float depth_range = 1.0f;  // far - near (world units), for the Listing 7.1 depth weight
  std::vector<float> luma;   // C weights of the gradient's scalar "norm" (Rec.709 luminance for R,G,B)
  const Options* options = nullptr;
  bool debug = false;        // add the debug.* layers
  // This frame's samples: tap tables of the jittered grid and the geometry (z, N) of each low-resolution sample
  // at its full-resolution pixel, with its validity (0 for a non-finite payload or geometry). Empty when the
  // method's state gathers its sample geometry itself, row by row (MethodState::gathers_low_geometry).
  TapTable cols, rows;
  std::vector<float> lz, lnx, lny, lnz, lvalid;
};

// Fills the sample geometry of `f` (lz .. lvalid) from its G-buffer and payload planes.
void gather_low_geometry(FrameContext& f);
// Empties the sample geometry of `f` (a method that gathers its own: nothing reads stale rows of an earlier frame).
void clear_low_geometry(FrameContext& f);

// Depth and ids of the previous frame, for the disocclusion test of the history fetch.
struct PreviousGeometry {
  PlaneVector<float> z;
  PlaneVector<std::uint32_t> id;  // empty when the G-buffer has no ids
  void store(const FrameContext& f);
};

// The history taps of full-resolution row Y (temporal/core/reproject.h): the previous frame's depth and ids, this
// frame's G-buffer, the disocclusion settings of the options. The expected previous depth is the warped depth
// prevDepth.Z when the frame has it (seed 000 section 3.2), else the current depth.
using reproject::HistoryRow;
inline reproject::Frames history_frames(const FrameContext& f, const PreviousGeometry& prev) {
  reproject::Frames fr;
  fr.width = f.W;
  fr.height = f.H;
  fr.motion_x = f.mx;
  fr.motion_y = f.my;
  fr.prev_z = prev.z.data();
  fr.id = f.id;
  fr.prev_id = prev.id.empty() ? nullptr : prev.id.data();
  fr.test = f.options->surface_test();
  reproject::expect_depth(fr, f.z, f.prev_z, f.options->warped_depth_tolerance);
  return fr;
}
inline void history_row(const FrameContext& f, const PreviousGeometry& prev, int Y, HistoryRow& h) {
  reproject::reproject_row(history_frames(f, prev), Y, h);
}
// history_row and the gather of n previous-frame planes src into dst in one pass (reproject::reproject_gather_row:
// the same values; h.w holds the weights of the gather runs only).
inline void history_gather_row(const FrameContext& f, const PreviousGeometry& prev, int Y, HistoryRow& h,
                               const float* const* src, float* const* dst, int n) {
  reproject::reproject_gather_row(history_frames(f, prev), Y, h, src, dst, n);
}

// The geometry (z, N, validity) and payload of one low-resolution row, expanded to full-resolution columns:
// plane q (0..4: z, nx, ny, nz, valid; 5 + c: payload channel c) holds W + k values, value[low_row + ext[X]]
// with ext[X] = clamp(floor((X - sx) / k), 0, lw - 1) (W = k lw). Tap i0 of column X is entry X and tap
// i1 (x0 + 1) is entry X + k, so one expansion serves both. A run of k full-resolution rows reads the same
// two low rows: expanding them once turns the per-pixel gathers of the kernel loops into unit-stride loads.
// Two slots: the rows r0, r1 of the current full row; a band walking down reuses r1 as the next r0.
class ExpandedLowRows {
 public:
  // Forget the cached rows (the low-resolution data changes every frame: call at the start of each band).
  void reset(int W, int k, int sx, int C) {
    WE_ = W + k;
    k_ = k;
    sx_ = sx;
    planes_ = 5 + C;
    for (auto& sl : slot_) {
      sl.key = -1;
      sl.v.resize(std::size_t(planes_) * WE_);
    }
  }
  std::size_t stride() const { return std::size_t(WE_); }
  // Slot pointers for the low rows starting at offsets r0 and r1 (row * lw), filled when not cached.
  void get(const FrameContext& f, int r0, int r1, const float*& p0, const float*& p1) {
    int a = find(r0);
    if (a < 0) {
      a = slot_[0].key == r1 ? 1 : 0;
      fill(f, r0, slot_[a]);
    }
    int b = find(r1);
    if (b < 0) {
      b = 1 - a;
      fill(f, r1, slot_[b]);
    }
    p0 = slot_[a].v.data();
    p1 = slot_[b].v.data();
  }

 private:
  struct Slot {
    int key = -1;
    std::vector<float> v;
  };
  int find(int r) const { return slot_[0].key == r ? 0 : (slot_[1].key == r ? 1 : -1); }
  void fill(const FrameContext& f, int r, Slot& sl) {
    const float* src[5 + 16] = {f.lz.data() + r, f.lnx.data() + r, f.lny.data() + r, f.lnz.data() + r,
                                f.lvalid.data() + r};
    for (int c = 0; c < f.C; ++c) src[5 + c] = f.low[c] + r;
    for (int q = 0; q < planes_; ++q) expand(src[q], sl.v.data() + std::size_t(q) * WE_, f.lw);
    sl.key = r;
  }
  // out[X] = in[clamp(floor((X - sx) / k), 0, lw - 1)] for X in [0, W + k): each sample repeated k times
  // (stores only; a gather per entry is several times slower). k = 2 and 4 get loops the compiler vectorises.
  [[gnu::noinline]] void expand(const float* __restrict in, float* __restrict out, int lw) const {
    const int k = k_, sx = sx_;
    for (int X = 0; X < sx; ++X) out[X] = in[0];
    float* __restrict o = out + sx;
    if (k == 4) {
      for (int x = 0; x < lw; ++x) {
        const float v = in[x];
        o[4 * x] = v;
        o[4 * x + 1] = v;
        o[4 * x + 2] = v;
        o[4 * x + 3] = v;
      }
    } else if (k == 2) {
      for (int x = 0; x < lw; ++x) {
        const float v = in[x];
        o[2 * x] = v;
        o[2 * x + 1] = v;
      }
    } else {
      for (int x = 0; x < lw; ++x)
        for (int i = 0; i < k; ++i) o[k * x + i] = in[x];
    }
    for (int X = sx + k * lw; X < WE_; ++X) out[X] = in[lw - 1];
  }
  int WE_ = 0, planes_ = 0, k_ = 1, sx_ = 0;
  Slot slot_[2];
};

// Geometric weight of one low-resolution sample (normal nl, depth lz, validity lv: 0 for a non-finite sample)
// for a pixel of depth zi and normal a: eq. 2's n * d (geometric_weight of joint_bilateral.h) times the validity;
// 0 when the pixel's own geometry is NaN. Every joint-bilateral kernel uses it, so they agree to the bit.
inline float sample_weight(float zi, float ax, float ay, float az, float lx, float ly, float lnz, float lz, float lv,
                           float inv_sn2, float inv_sd2) {
  const float dot = ax * lx + ay * ly + az * lnz;
  const float w = geometric_weight(dot, zi - lz, inv_sn2, inv_sd2) * lv;
  return w >= 0.0f ? w : 0.0f;
}

// spatial's and herzog's geometric weights of a full row (expanded_geometric_weights) are in geometric_weights.inc,
// compiled in each instruction-set copy.

// Joint-bilateral upsampling (eq. 1-3, hat kernel) of full-resolution row Y, columns [X0, X1) (X1 < 0: to the
// end of the row), into out[c][X0 .. X1) (out rows are indexed by X); `wsum` (a row indexed by X) receives the
// sum of weights when not null. Shared by `spatial` and the hole filling of `temporal` (only the hole runs).
void spatial_row(const FrameContext& f, int Y, float* const* out, float* wsum, int X0 = 0, int X1 = -1);

}  // namespace temporal::upsample
