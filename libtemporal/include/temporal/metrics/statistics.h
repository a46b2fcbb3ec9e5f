// Statistics a reviewer accepts for "A beats B" (docs/compare.md, "Intervals"): the mean of a per-frame metric
// with a 95 % bootstrap interval, and the paired difference of two methods measured on the same frames with its
// interval.
//
// Frames of a sequence are not independent (a temporal method's error at frame t carries into t + 1), so an
// ordinary bootstrap that resamples single frames would make the intervals too narrow. The moving-block bootstrap
// (Kunsch 1989) resamples runs of L consecutive frames instead (circularly, Politis & Romano 1992), with
// L = round(n^(1/3)) by default (Hall, Horowitz & Jing 1995: the order of the optimal block length for the
// variance of a mean); the interval is the percentile interval of the resampled means. Resampling uses a fixed
// seed, so the same series always gives the same interval.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

namespace temporal {

struct Interval {
  double low = 0.0;
  double high = 0.0;
};

struct BootstrapOptions {
  double level = 0.95;     // coverage of the interval
  int resamples = 2000;    // bootstrap resamples
  int block = 0;           // block length in frames; 0 = round(n^(1/3)), at least 1
  unsigned seed = 20101;   // resampling seed (fixed: results are reproducible)
};

// The mean of `series` and its bootstrap interval. NaN values (frames without a value) are left out first;
// +infinity (a PSNR of identical frames) is kept, so a series with one infinite frame has an infinite mean, and
// an interval that reaches infinity when resamples include it. Empty series: NaN mean and interval. A constant
// series has an interval of zero width.
struct MeanInterval {
  std::size_t count = 0;     // values used
  std::size_t infinite = 0;  // of which +-infinite
  double mean = 0.0;
  Interval ci;
};
MeanInterval bootstrap_mean(std::span<const double> series, const BootstrapOptions& options = {});

// The paired difference a_t - b_t over the frames where both have a value, with its bootstrap interval (blocks
// of frames, as above). Two infinite values of the same sign are a tie (difference 0: both methods reproduced
// the reference exactly); one infinite value gives an infinite difference.
MeanInterval bootstrap_paired_difference(std::span<const double> a, std::span<const double> b,
                                         const BootstrapOptions& options = {});

// Pooled PSNR (docs/compare.md, "Pooled PSNR"): the PSNR of the squared error pooled over every pixel of every
// frame, from per-frame PSNRs p_t (dB) and pixel counts w_t:
//     pooled = -10 log10( sum_t w_t 10^(-p_t / 10) / sum_t w_t ),
// since 10^(-p_t/10) = MSE_t / L_t^2 is frame t's normalised mean squared error (= 10 log10(L^2 / pooled MSE) for a
// fixed peak L). Unlike the mean of p_t it is not dominated by the best frames: one frame with 100x the error of
// the others moves it by up to 20 dB, the mean of p_t by 20 dB / n. Frames with a NaN PSNR or a weight <= 0 are
// left out; +inf frames (identical images) add no error; one -inf frame (an overflowing error) makes it -inf.
// No frame: NaN.
double pooled_psnr(std::span<const double> psnr, std::span<const double> weight);
// The pooled PSNR with a bootstrap interval: the same moving blocks of frames as bootstrap_mean, the statistic
// recomputed on each resample (the pooled value is a ratio of sums over frames, not a mean, so the interval is
// the percentile interval of the resampled pooled values). `count` is the number of frames used, `mean` the pooled
// PSNR of all of them.
MeanInterval bootstrap_pooled_psnr(std::span<const double> psnr, std::span<const double> weight,
                                   const BootstrapOptions& options = {});
// pooled(a) - pooled(b) over the frames where both have a value, with its interval from resampling the same blocks
// of frames for both (paired). Two +inf pooled values are a tie (0), as in bootstrap_paired_difference.
MeanInterval bootstrap_pooled_psnr_difference(std::span<const double> psnr_a, std::span<const double> weight_a,
                                              std::span<const double> psnr_b, std::span<const double> weight_b,
                                              const BootstrapOptions& options = {});

}  // namespace temporal
