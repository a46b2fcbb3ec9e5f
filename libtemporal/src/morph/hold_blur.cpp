// Hold-type blur under smooth pursuit (seed 004 section 3, Figure 1): the eye moves continuously while each
// frame is held, so a point of the retina integrates the held frame along the motion path.
#include "temporal/morph/hold_blur.h"

#include "temporal/core/isa.h"
#include "temporal/core/parallel.h"
#include "temporal/core/reproject.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace temporal::morph {
namespace {

// The integration copies, one per instruction set (temporal/core/isa.h). v3 and v4 contract the eye position
// c + t v and the bilinear sums into FMAs (v2 has none): v2 differs from them in the last bits
// (tests/core/isa_test.cpp); v3 and v4 are bit-identical.
#define TEMPORAL_ISA_FILE "hold_blur_kernels.inc"
#include "temporal/core/isa_copies.inc"

void perceive_rows_copy(const float* const* src, float* const* dst, std::size_t count, std::size_t nc,
                        const float* motion_x, const float* motion_y, int w, int h, float spp, int max_samples) {
  TEMPORAL_ISA_CALL(copy, return copy::perceive_rows(src, dst, count, nc, motion_x, motion_y, w, h, spp, max_samples))
}

}  // namespace

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
  perceive_rows_copy(src.data(), dst.data(), count, nc, motion_x, motion_y, w, h, spp, options.max_samples);
  out.metadata() = frames[0]->metadata();
  return out;
}

namespace {

// perceived(r + tau * motion(r)) into out (one plane per channel). Pixel centres are at integers in the
// reprojection module's coordinates.
void shift_along_motion(std::span<const float* const> src, std::span<float* const> dst, const float* mx,
                        const float* my, int w, int h, float tau) {
  parallel_rows(h, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < w; ++x) {
        const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
        const float vx = std::isfinite(mx[i]) ? mx[i] : 0.0f, vy = std::isfinite(my[i]) ? my[i] : 0.0f;
        const reproject::Bilinear b = reproject::bilinear(float(x) + tau * vx, float(y) + tau * vy, w, h);
        for (std::size_t c = 0; c < src.size(); ++c) dst[c][i] = b(src[c]);
      }
  });
}

}  // namespace

Expected<LagAlignment> align_lag(const Image& perceived, const Image& reference, const std::vector<std::string>& channels,
                                 const float* motion_x, const float* motion_y, const LagSearchOptions& options) {
  if (!(options.max_lag_frames >= 0.0f) || !(options.coarse_step > 0.0f) || !(options.fine_step > 0.0f) ||
      !std::isfinite(options.max_lag_frames))
    return Error::usage("align_lag: max_lag_frames must be >= 0 and the steps > 0");
  if (!motion_x || !motion_y) return Error::input({}, "align_lag: the motion layer (motion.X, motion.Y) is missing");
  const int w = perceived.width(), h = perceived.height();
  if (reference.width() != w || reference.height() != h)
    return Error::input({}, "align_lag: the reference's perceived image has another size");
  const std::size_t nc = channels.size(), n = perceived.pixel_count();
  std::vector<const float*> src(nc), ref(nc);
  for (std::size_t c = 0; c < nc; ++c) {
    src[c] = perceived.plane(channels[c]);
    ref[c] = reference.plane(channels[c]);
    if (!src[c] || !ref[c]) return Error::input({}, "align_lag: no float channel '" + channels[c] + "'");
  }
  LagAlignment result;
  result.aligned = Image(w, h);
  std::vector<float*> dst(nc);
  for (std::size_t c = 0; c < nc; ++c) dst[c] = result.aligned.add_channel(channels[c]);
  std::vector<double> row_sum(static_cast<std::size_t>(h));
  // Mean squared error of the image shifted by tau; rows summed in order, so the result does not depend on the
  // thread count. Non-finite values (never written by the stage) would be skipped.
  auto error_at = [&](float tau) {
    shift_along_motion(src, dst, motion_x, motion_y, w, h, tau);
    parallel_rows(h, [&](int y0, int y1) {
      for (int y = y0; y < y1; ++y) {
        double s = 0.0;
        for (std::size_t c = 0; c < nc; ++c)
          for (int x = 0; x < w; ++x) {
            const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
            const double d = double(dst[c][i]) - double(ref[c][i]);
            if (std::isfinite(d)) s += d * d;
          }
        row_sum[std::size_t(y)] = s;
      }
    });
    double s = 0.0;
    for (const double r : row_sum) s += r;
    return s / double(std::max<std::size_t>(1, n * nc));
  };
  // Candidates in order of |tau| (0, +s, -s, +2s, ...): a later one must be better by a relative 1e-9 to win,
  // so ties go to the smallest lag.
  float best = 0.0f;
  double best_err = error_at(0.0f);
  result.mse_unaligned = best_err;
  auto consider = [&](float tau) {
    const double e = error_at(tau);
    if (e < best_err * (1.0 - 1e-9)) {
      best_err = e;
      best = tau;
    }
  };
  const int coarse = int(std::floor(options.max_lag_frames / options.coarse_step + 1e-6f));
  for (int k = 1; k <= coarse; ++k)
    for (const float sign : {1.0f, -1.0f}) consider(sign * float(k) * options.coarse_step);
  const float centre = best;
  const int fine = int(std::floor(options.coarse_step / options.fine_step + 1e-6f));
  for (int k = 1; k <= fine; ++k)
    for (const float sign : {1.0f, -1.0f}) {
      const float tau = centre + sign * float(k) * options.fine_step;
      if (std::fabs(tau) <= options.max_lag_frames + 1e-6f) consider(tau);
    }
  result.lag_frames = best;
  result.mse = error_at(best);  // also leaves the best shift in `aligned`
  return result;
}

}  // namespace temporal::morph
