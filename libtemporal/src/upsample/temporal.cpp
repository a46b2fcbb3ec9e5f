// `temporal`: temporally-amortised upsampling, seed 000 section 3.2, eq. 4 with the binary weight w_t:
// a pixel shaded this frame (w_t = 1) takes the new sample, every other pixel takes the previous output at
// its motion-compensated position. Disocclusions (warped depth + material id, Figure 3) and pixels that
// leave the screen have no history: the paper re-renders them in a second pass; we count them
// (FrameStats::hole_pixels, `temporal:holePixels`) and fill them with the joint-bilateral result (eq. 1-3).
#include "method.h"
#include "gpu_methods.h"

#include "temporal/core/parallel.h"

#include <atomic>

namespace temporal::upsample {

namespace {

// Eq. 4 for one frame: the new samples, the previous output at p + motion elsewhere, the spatial result in the
// holes.
void temporal_frame(const FrameContext& f, const PreviousGeometry& prev_geo, bool history, Image& out,
                    const Image& prev, const std::vector<std::string>& channels, FrameStats& stats) {
  const int C = f.C;
  const std::vector<float*> planes = payload_planes(out, channels);
  const std::vector<const float*> prev_planes = payload_planes(prev, channels);
  float* dbg_disocc = f.debug ? out.add_channel("debug.disocclusion") : nullptr;
  float* dbg_conf = f.debug ? out.add_channel("debug.confidence") : nullptr;
  std::atomic<std::size_t> holes{0}, hits{0};
  parallel_rows(f.H, [&](int y0, int y1) {
    thread_local std::vector<float> fill, computed, hole;
    thread_local HistoryRow hist;
    fill.resize(std::size_t(C) * f.W);
    computed.resize(f.W);
    hole.resize(f.W);
    std::vector<float*> fill_rows(C);
    for (int c = 0; c < C; ++c) fill_rows[c] = fill.data() + std::size_t(c) * f.W;
    std::size_t band_holes = 0, band_hits = 0;
    for (int Y = y0; Y < y1; ++Y) {
      const std::size_t row = std::size_t(Y) * f.W;
      const bool row_computed = f.rows.d[Y] == 0;
      const std::size_t lrow = std::size_t(f.rows.i0[Y]) * f.lw;
      // w_t of eq. 4: 1 where this frame shaded the pixel (and the sample is finite).
      for (int X = 0; X < f.W; ++X)
        computed[X] = (row_computed && f.cols.d[X] == 0 && f.lvalid[lrow + f.cols.i0[X]] > 0) ? 1.0f : 0.0f;
      if (history) {
        history_row(f, prev_geo, Y, hist);
      } else {
        hist.resize(f.W);
        std::fill(hist.hit.begin(), hist.hit.end(), 0.0f);
      }
      std::size_t row_holes = 0, row_hits = 0;
      for (int X = 0; X < f.W; ++X) {
        hole[X] = (computed[X] == 0.0f && hist.hit[X] == 0.0f) ? 1.0f : 0.0f;
        row_holes += hole[X] > 0 ? 1 : 0;
        row_hits += (computed[X] == 0.0f && hist.hit[X] > 0.0f) ? 1 : 0;
      }
      if (history) {  // eq. 4, w_t = 0: the previous output at p + motion
        for (int c0 = 0; c0 < C; c0 += 4) {
          const float* src[4];
          float* dst[4];
          const int n = std::min(4, C - c0);
          for (int i = 0; i < n; ++i) {
            src[i] = prev_planes[c0 + i];
            dst[i] = planes[c0 + i] + row;
          }
          reproject::gather_row(hist, src, dst, n, f.W);
        }
      }
      for (int c = 0; c < C; ++c) {
        float* out_row = planes[c] + row;
        const float* l = f.low[c] + lrow;
        const int* ci0 = f.cols.i0.data();
        for (int X = 0; X < f.W; ++X) {
          const float h = history && hist.hit[X] > 0 ? out_row[X] : 0.0f;
          out_row[X] = computed[X] > 0 ? l[ci0[X]] : h;  // eq. 4, w_t = 1
        }
      }
      if (dbg_conf) {
        spatial_row(f, Y, fill_rows.data(), dbg_conf + row);
        for (int c = 0; c < C; ++c)
          for (int X = 0; X < f.W; ++X)
            if (hole[X] > 0) planes[c][row + X] = fill_rows[c][X];
      } else if (row_holes > 0) {
        // Only the runs of holes (typically a few pixels at a disocclusion or the screen edge) are upsampled
        // spatially; runs less than 16 pixels apart are merged to keep the kernel loops long.
        int X = 0;
        while (X < f.W) {
          while (X < f.W && hole[X] == 0.0f) ++X;
          if (X >= f.W) break;
          const int a = X;
          int b = X, gap = 0;
          for (; X < f.W && gap < 16; ++X) {
            if (hole[X] > 0) {
              b = X + 1;
              gap = 0;
            } else {
              ++gap;
            }
          }
          X = b;
          spatial_row(f, Y, fill_rows.data(), nullptr, a, b);
          for (int c = 0; c < C; ++c)
            for (int x = a; x < b; ++x)
              if (hole[x] > 0) planes[c][row + x] = fill_rows[c][x];
        }
      }
      if (dbg_disocc)
        for (int X = 0; X < f.W; ++X) dbg_disocc[row + X] = hole[X];
      band_holes += row_holes;
      band_hits += row_hits;
    }
    holes += band_holes;
    hits += band_hits;
  });
  stats.hole_pixels = holes;
  stats.history_pixels = hits;
}

// The previous output (the history) and the previous frame's depth and ids.
class TemporalState : public MethodState {
 public:
  explicit TemporalState(const Geometry& g) : out_(g), g_(g) {}

  Image& run(const FrameContext& f, bool history, FrameStats& stats) override {
    Image& out = out_.next();
    temporal_frame(f, prev_, history, out, out_.previous(), g_.channels, stats);
    prev_.store(f);
    return out;
  }
  void save(Image& state) const override {
    for (const auto& c : g_.channels) put_plane(state, "history." + c, out_.current().plane(c), g_.W, g_.H);
    put_previous(state, prev_, g_.W, g_.H);
  }
  Status load(const Image& state) override {
    Image& out = out_.next();
    for (const auto& c : g_.channels)
      if (Status s = get_plane(state, "history." + c, out.plane(c), g_.W, g_.H); !s) return s;
    return get_previous(state, prev_, g_.W, g_.H);
  }

 private:
  OutputPair out_;
  Geometry g_;
  PreviousGeometry prev_;
};

// depth + N, payload in and out; motion, id; the previous depth and id read and written; the history read.
std::size_t streamed_bytes(const Options&, int W, int H, int k, int C) {
  const std::size_t full = std::size_t(W) * H * 4, low = full / (std::size_t(k) * k);
  return 4 * full + C * low + C * full + 2 * full + full + 2 * (2 * full) + C * full;
}

}  // namespace

const MethodEntry& temporal_method() {
  static const MethodEntry entry{
      .info = {.name = "temporal",
               .summary = "temporally-amortised upsampling (seed 000 section 3.2, eq. 4): new samples kept, the "
                          "previous output at p + motion elsewhere, holes filled spatially",
               .has_state = true},
      .layers = history_method_layers,
      .implementations = {{kCpuDevice,
                           [](const Options&, const Geometry& g) -> std::unique_ptr<MethodState> {
                             return std::make_unique<TemporalState>(g);
                           }},
                          // temporal_gpu.cpp: eq. 4 as one GLSL kernel, the same state planes.
                          {kGpuDevice, gpu_implementation<make_temporal_state_gpu>}},
      .streamed_bytes = streamed_bytes};
  return entry;
}

}  // namespace temporal::upsample
