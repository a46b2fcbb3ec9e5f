// `spatial`: joint-bilateral upsampling, seed 000 section 3.1 (eq. 1-3) with the hat image kernel of
// [Yang et al. 2008]. The per-row kernel (spatial_row) lives in upsampler.cpp because `temporal` reuses it.
#include "upsample_internal.h"

#include "temporal/parallel.h"

namespace temporal::upsample {

void run_spatial(Upsampler::State& s, const FrameContext& f, const Options& o, FrameStats& stats) {
  Image& out = s.result[s.cur];
  std::vector<float*> planes;
  for (const auto& c : s.channels) planes.push_back(out.plane(c));
  float* conf = o.debug_layers ? out.add_channel("debug.confidence") : nullptr;
  parallel_rows(f.H, [&](int y0, int y1) {
    std::vector<float*> rows(planes.size());
    for (int Y = y0; Y < y1; ++Y) {
      const std::size_t off = std::size_t(Y) * f.W;
      for (std::size_t c = 0; c < planes.size(); ++c) rows[c] = planes[c] + off;
      spatial_row(s, f, o, Y, rows.data(), conf ? conf + off : nullptr);
    }
  });
  stats.hole_pixels = 0;
  stats.history_pixels = 0;
}

}  // namespace temporal::upsample
