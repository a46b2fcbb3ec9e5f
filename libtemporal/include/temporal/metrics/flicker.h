// Temporal instability ("flicker") of a test sequence relative to its reference.
//
// For frame t, with T the test's and R the reference's luminance and W the motion-compensated fetch of the
// previous frame (temporal/metrics/warp.h; the identity without motion vectors):
//
//   d_t(p) = (T_t(p) - W(T_{t-1})(p)) - (R_t(p) - W(R_{t-1})(p))
//   flicker_t = sqrt( mean over compared pixels p of d_t(p)^2 )        (RMS, in the units of the pixel values)
//
// The reference's own frame-to-frame change (moving light, animation) is subtracted, so only the change the
// method adds or removes counts: a test equal to the reference gives 0, a test that flickers around it gives its
// RMS temporal noise, and a test that lags behind a real change (ghosting, over-blur) is also penalised.
// Pixels whose history is unavailable (p_prev outside the image, a NaN/Inf in either frame) are not compared.
#pragma once

#include <cstddef>
#include <cstdint>

namespace temporal {

struct FlickerResult {
  double sum_sq = 0.0;  // sum of d^2 over compared pixels
  std::size_t pixels = 0;
  double sum_sq_inside = 0.0;  // pixels with mask > 0.5
  std::size_t pixels_inside = 0;
  double sum_sq_outside = 0.0;
  std::size_t pixels_outside = 0;
  // RMS of d over the pixels of each region; 0 when the region is empty.
  double rms() const;
  double rms_inside() const;
  double rms_outside() const;
};

// delta = current - previous_warped (one plane of `count` floats); NaN where previous_warped is NaN. `delta`
// may be `previous_warped` (in place).
void temporal_delta(const float* current, const float* previous_warped, std::size_t count, float* delta);

// Flicker of one frame: test_delta and reference_delta from temporal_delta(); a pixel is compared when
// valid != 0 (current frame finite; may be null = all) and both deltas are finite. `mask` (may be null) splits the
// sums (inside: mask > 0.5). `map` (may be null) receives |d|, 0 where the pixel was not compared.
FlickerResult flicker(const float* test_delta, const float* reference_delta, int width, int height,
                      const std::uint8_t* valid, const float* mask, float* map = nullptr);

}  // namespace temporal
