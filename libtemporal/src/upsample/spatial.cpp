// `spatial`: joint-bilateral upsampling, seed 000 section 3.1 (eq. 1-3) with the hat image kernel of
// [Yang et al. 2008]. Whole frames read the two low rows of each full row expanded to full-resolution columns
// (ExpandedLowRows, shared with herzog's pass A): unit-stride loads instead of ~32 gathers per pixel. The
// gathering version (spatial_row, in frame.cpp) serves `temporal`'s sparse hole runs; both compute the
// same weights in the same order, so their results are bit-identical.
#include "method.h"
#include "gpu_methods.h"

#include "temporal/core/parallel.h"

namespace temporal::upsample {
namespace {

// Eq. 1-3 for full row Y from the expanded low rows e0 (row i0) and e1 (row i1), plane stride es: out[c] and
// (when not null) the sum of weights.
void spatial_row_expanded(const FrameContext& f, int Y, const float* e0, const float* e1, std::size_t es,
                          float* const* out, float* wsum, float* w4) {
  const Options& o = *f.options;
  const int W = f.W, k = f.grid.k;
  float* __restrict w00 = w4;
  float* __restrict w01 = w00 + W;
  float* __restrict w10 = w01 + W;
  float* __restrict w11 = w10 + W;
  const float fy = float(f.rows.d[Y]) / float(k), inv_k = 1.0f / float(k);
  const float inv_sn2 = 1.0f / (o.sigma_normal * o.sigma_normal), inv_sd2 = 1.0f / (f.sigma_d * f.sigma_d);
  const int* __restrict cd = f.cols.d.data();
  // Plane q, tap t (0: column i0, 1: column i1 = the i0 expansion shifted by k) of an expanded low row.
  auto ex = [es, k](const float* e, int q, int t) { return e + std::size_t(q) * es + std::size_t(t) * k; };
  // Geometric weights (eq. 2-3) times tap existence, then the hat image kernel (bilinear in the offset).
  expanded_geometric_weights(f, inv_sn2, inv_sd2, Y, e0, e1, es, w00, w01, w10, w11);
#pragma GCC ivdep
  for (int X = 0; X < W; ++X) {
    const float fx = float(cd[X]) * inv_k;
    w00[X] = w00[X] * (1 - fx) * (1 - fy);
    w01[X] = w01[X] * fx * (1 - fy);
    w10[X] = w10[X] * (1 - fx) * fy;
    w11[X] = w11[X] * fx * fy;
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


// Spatial upsampling keeps nothing between frames: its state is its output image.
class SpatialState : public MethodState {
 public:
  explicit SpatialState(const Geometry& g) : out_(g), channels_(g.channels) {}

  Image& run(const FrameContext& f, bool, FrameStats& stats) override {
    Image& out = out_.next();
    const std::vector<float*> planes = payload_planes(out, channels_);
    float* conf = f.debug ? out.add_channel("debug.confidence") : nullptr;
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
        low_rows.get(f, f.rows.i0[Y] * f.lw, f.rows.i1[Y] * f.lw, e0, e1);
        spatial_row_expanded(f, Y, e0, e1, low_rows.stride(), rows, conf ? conf + off : nullptr, w4.data());
      }
    }, 16);
    stats.hole_pixels = 0;
    stats.history_pixels = 0;
    return out;
  }
  void save(Image&) const override {}
  Status load(const Image&) override { return Status::ok(); }

 private:
  OutputPair out_;
  std::vector<std::string> channels_;
};

std::vector<LayerNeed> layers(const Options&) { return {{"depth"}, {"N"}}; }

// Reads depth + N (4 planes) and the payload, writes the output; nothing else.
std::size_t streamed_bytes(const Options&, int W, int H, int k, int C) {
  const std::size_t full = std::size_t(W) * H * 4, low = full / (std::size_t(k) * k);
  return 4 * full + C * low + C * full;
}

}  // namespace

const MethodEntry& spatial_method() {
  static const MethodEntry entry{
      .info = {.name = "spatial",
               .summary = "joint-bilateral upsampling of this frame's samples (seed 000 section 3.1, eq. 1-3, hat "
                          "kernel)"},
      .layers = layers,
      .implementations = {{kCpuDevice,
                           [](const Options&, const Geometry& g) -> std::unique_ptr<MethodState> {
                             return std::make_unique<SpatialState>(g);
                           }},
                          // spatial_gpu.cpp: eq. 1-3 as one GLSL kernel.
                          {kGpuDevice, gpu_implementation<make_spatial_state_gpu>}},
      .streamed_bytes = streamed_bytes};
  return entry;
}

}  // namespace temporal::upsample
