// Hold-type blur under smooth pursuit (seed 004 section 3, Figure 1): the eye moves continuously while each
// frame is held, so a point of the retina integrates the held frame along the motion path.
#include "temporal/morph/hold_blur.h"

#include "temporal/core/parallel.h"
#include "temporal/core/reproject.h"

#include <algorithm>
#include <cmath>

namespace temporal {

Expected<Image> perceive_hold(std::span<const Image* const> frames, const std::vector<std::string>& channels,
                              const float* motion_x, const float* motion_y, const HoldBlurOptions& options) {
  if (frames.empty() || !frames[0]) return Error::input({}, "perceive_hold: no frame given");
  if (options.window < 1 || options.samples_per_pixel < 1 || options.max_samples < 1)
    return Error::usage("perceive_hold: window, samples_per_pixel and max_samples must be at least 1");
  if (!motion_x || !motion_y) return Error::input({}, "perceive_hold: the motion layer (motion.X, motion.Y) is missing");
  const int w = frames[0]->width(), h = frames[0]->height();
  const std::size_t count = std::min<std::size_t>(frames.size(), std::size_t(options.window));
  for (std::size_t f = 0; f < count; ++f) {
    if (!frames[f] || frames[f]->width() != w || frames[f]->height() != h)
      return Error::input({}, "perceive_hold: displayed frame " + std::to_string(f) + " of the window is missing or has another size");
    for (const auto& ch : channels)
      if (!frames[f]->plane(ch)) return Error::input({}, "perceive_hold: a displayed frame has no float channel '" + ch + "'");
  }
  Image out(w, h);
  for (const auto& ch : channels) out.add_channel(ch);
  const float spp = float(options.samples_per_pixel);
  const std::size_t nc = channels.size();
  // src[f * nc + c]: plane of channel c in window frame f; dst[c]: output plane.
  std::vector<const float*> src(count * nc);
  std::vector<float*> dst(nc);
  for (std::size_t c = 0; c < nc; ++c) {
    dst[c] = out.plane(channels[c]);
    for (std::size_t f = 0; f < count; ++f) src[f * nc + c] = frames[f]->plane(channels[c]);
  }
  parallel_rows(h, [&](int y0, int y1) {
    std::vector<double> sum(nc);  // one per band of rows, never per pixel
    for (int y = y0; y < y1; ++y) {
      for (int x = 0; x < w; ++x) {
        const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
        float vx = -motion_x[i], vy = -motion_y[i];  // screen velocity, pixels per displayed frame
        if (!std::isfinite(vx) || !std::isfinite(vy)) vx = vy = 0.0f;
        const float speed = std::sqrt(vx * vx + vy * vy);
        const int samples = std::clamp(int(std::ceil(speed * spp)), 1, options.max_samples);
        const float cx = float(x) + 0.5f, cy = float(y) + 0.5f;
        std::fill(sum.begin(), sum.end(), 0.0);
        for (std::size_t f = 0; f < count; ++f) {
          // Midpoint rule over the hold time of frame f: the eye is at (f + s) * v, s in [0, 1). One bilinear
          // fetch of the reprojection module (pixel centres at integers there, edge taps repeated) serves every
          // channel.
          for (int s = 0; s < samples; ++s) {
            const float tt = float(f) + (float(s) + 0.5f) / float(samples);
            const float fx = cx + tt * vx - 0.5f, fy = cy + tt * vy - 0.5f;
            const reproject::Bilinear b = reproject::bilinear(fx, fy, w, h);
            for (std::size_t c = 0; c < nc; ++c) sum[c] += b(src[f * nc + c]);
          }
        }
        const double norm = 1.0 / (double(samples) * double(count));
        for (std::size_t c = 0; c < nc; ++c) dst[c][i] = float(sum[c] * norm);
      }
    }
  });
  out.metadata() = frames[0]->metadata();
  return out;
}

}  // namespace temporal
