// The reprojection module (temporal/core/reproject.h): the row kernels every history method and metric uses.
//
// reproject_row works in two steps per row: (1) per pixel, the tap indices, the bilinear weights of the taps and
// the run structure, without touching the previous frame (a loop that vectorises, no gathers); (2) per segment,
// the depth / id tests against the previous frame, with contiguous loads where the taps are aligned (most of a
// typical frame) and gathers elsewhere. Same values as testing everything in one gathered loop.
#include "temporal/core/reproject.h"

#include "temporal/core/isa.h"
#include "temporal/core/parallel.h"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

#include <bit>
#include <cstring>
#include <limits>

namespace temporal::reproject {

void HistoryRow::resize(int W) {
  for (auto& v : q) v.resize(W);
  for (auto& v : w) v.resize(W);
  hit.resize(W);
  offset.resize(W);
  aligned.resize(W);
}

namespace {

// The kernel copies, one per instruction set (temporal/core/isa.h). The bilinear sums w0 p0 + w1 p1 + ... may
// be contracted into fused multiply-adds in v3 and v4 (v2 has none): the history differs in the last bit there.
#define TEMPORAL_ISA_FILE "reproject_kernels.inc"
#include "temporal/core/isa_copies.inc"

struct Kernels {
  void (*reproject)(const Frames&, int, HistoryRow&);
  void (*gather)(const HistoryRow&, const float* const*, float* const*, int, int);
  void (*segments)(HistoryRow&, int);
  void (*reproject_gather)(const Frames&, int, HistoryRow&, const float* const*, float* const*, int);
};

const Kernels& kernels() {
#if TEMPORAL_ISA_DISPATCH
  static constexpr Kernels table[3] = {
      {v2::reproject_row_copy, v2::gather_row_copy, v2::build_segments_copy, v2::reproject_gather_row_copy},
      {v3::reproject_row_copy, v3::gather_row_copy, v3::build_segments_copy, v3::reproject_gather_row_copy},
      {v4::reproject_row_copy, v4::gather_row_copy, v4::build_segments_copy, v4::reproject_gather_row_copy}};
  return table[int(isa::active())];  // Level::V2, V3, V4 are 0, 1, 2
#else
  static constexpr Kernels table{native::reproject_row_copy, native::gather_row_copy, native::build_segments_copy,
                                 native::reproject_gather_row_copy};
  return table;
#endif
}

}  // namespace

void reproject_row(const Frames& frames, int y, HistoryRow& h) {
  h.resize(frames.width);
  kernels().reproject(frames, y, h);
}

void build_segments(HistoryRow& h, int width) { kernels().segments(h, width); }

void gather_row(const HistoryRow& h, const float* const* prev, float* const* out, int n, int width) {
  kernels().gather(h, prev, out, n, width);
}

void reproject_gather_row(const Frames& frames, int y, HistoryRow& h, const float* const* prev, float* const* out,
                          int n) {
  if (n > 4) {  // the fused loop holds up to four planes
    reproject_row(frames, y, h);
    gather_row(h, prev, out, n, frames.width);
    return;
  }
  // Only when a row changed size: HistoryRow::resize is eleven vector resizes, ~160 instructions a row at v3 even
  // when nothing changes (callgrind, issue 27's sixth herzog pass); herzog calls this once per row.
  const std::size_t W = std::size_t(frames.width);
  bool sized = h.hit.size() == W && h.offset.size() == W && h.aligned.size() == W;
  for (int j = 0; j < 4; ++j) sized = sized && h.q[j].size() == W && h.w[j].size() == W;
  if (!sized) h.resize(frames.width);
  kernels().reproject_gather(frames, y, h, prev, out, n);
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
