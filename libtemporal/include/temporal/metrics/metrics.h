// Image-quality metrics of the `compare` tool: PSNR, SSIM and error maps, over planar float buffers.
//
// Every function takes the compared channels as planes (one pointer per channel, same order in the test and
// the reference, width * height floats each, row-major without padding) and a per-pixel validity plane:
// a pixel where any compared channel of either image is NaN or +-Inf is invalid and enters no metric
// (docs/compare.md, "Non-finite pixels"). Results are deterministic: partial sums are kept per row in double
// precision and added in row order, so they do not depend on the thread count.
//
// Units: pixel values are whatever the images hold (scene-linear radiance for colour); PSNR is in dB against
// a peak value `peak` in the same units; SSIM is unitless in [-1, 1].
#pragma once

#include "temporal/core/fwd.h"

#include "temporal/core/error.h"

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace temporal {


// --- Channel selection ------------------------------------------------------------------------------------

// The channels that `--layer NAME` compares: select_layers (temporal/core/image.h, the rule of every tool), or
// empty when it finds none (where a missing layer is not an error, e.g. the mask's lookup).
std::vector<std::string> compared_channels(const Image& image, std::string_view layer);

// --- Per-pixel helpers (each parallel over rows) -----------------------------------------------------------

// Luminance of the compared channels: Rec.709 weights (0.2126, 0.7152, 0.0722) for three channels, the channel
// itself for one, the plain mean otherwise. `out` holds `count` floats.
void luminance_plane(std::span<const float* const> channels, std::size_t count, float* out);

// Writes 1 to valid[i] where every channel of `a` and of `b` is finite at pixel i, else 0, and returns the
// number of invalid pixels. `b` may be empty.
std::size_t finite_mask(std::span<const float* const> a, std::span<const float* const> b, std::size_t count,
                        std::uint8_t* valid);

// --- PSNR ------------------------------------------------------------------------------------------------

// Sum of squared differences over valid pixels, split by an optional mask (inside: mask > 0.5).
struct SquaredError {
  double sum = 0.0;           // sum over pixels and channels of (test - reference)^2
  std::size_t samples = 0;    // pixels * channels that entered `sum`
  double mean() const { return samples ? sum / double(samples) : 0.0; }
};
struct SquaredErrorSplit {
  SquaredError all, inside, outside;
};

// Squared error of `test` against `reference` (planes of `width * height` floats) at pixels with valid != 0.
// `mask` (may be null) splits the sum into inside (mask > 0.5) and outside.
SquaredErrorSplit squared_error(std::span<const float* const> test, std::span<const float* const> reference,
                                int width, int height, const std::uint8_t* valid, const float* mask);

// PSNR in dB: 10 log10(peak^2 / mse). Returns +infinity when mse == 0 (identical images) and NaN only when no
// pixel was compared (samples == 0), which callers report as "no value".
double psnr_db(const SquaredError& error, double peak);

// The largest finite value of the planes, at least 1: the peak `idiff` uses (OpenImageIO 2.4 takes the
// largest value of both images once it exceeds 1). Used by `compare --peak max`.
float idiff_peak(std::span<const float* const> planes, std::size_t count);

// --- SSIM (Wang, Bovik, Sheikh, Simoncelli 2004, "Image quality assessment: from error visibility to
// structural similarity", eq. 13 with the constants of its section III-C) ----------------------------------

struct SsimOptions {
  double peak = 1.0;   // L, the dynamic range of the pixel values
  double k1 = 0.01;    // C1 = (K1 L)^2
  double k2 = 0.03;    // C2 = (K2 L)^2
  double sigma = 1.5;  // standard deviation of the Gaussian window, pixels
  int radius = 5;      // window is (2 radius + 1)^2 = 11x11, normalised to sum 1
};

struct SsimResult {
  double mean = 0.0;                  // MSSIM: mean of the SSIM map over the windows that were evaluated
  std::size_t windows = 0;            // windows evaluated
  double mean_inside = 0.0;           // mean over windows whose centre has mask > 0.5
  std::size_t windows_inside = 0;
  double mean_outside = 0.0;
  std::size_t windows_outside = 0;
};

// Mean SSIM of two single-channel planes (`width * height` floats), as Wang et al.'s reference code
// ssim_index.m computes it: local statistics under the Gaussian window (biased, weights sum to 1), and only
// windows that lie entirely inside the image ("valid" filtering), so the map covers the
// (width - 2 radius) x (height - 2 radius) window centres. Invalid pixels (valid == 0) get zero weight inside
// every window and the local statistics are renormalised by the remaining weight; windows centred on an invalid
// pixel are skipped. With every pixel valid this is exactly Wang et al.'s MSSIM. `mask` splits the mean by the
// window centre. `map` (may be null) receives 1 - SSIM at each window centre and 0 elsewhere.
// Error (Input) when the image is smaller than the window.
Expected<SsimResult> ssim(const float* test, const float* reference, int width, int height,
                          const std::uint8_t* valid, const float* mask, const SsimOptions& options,
                          float* map = nullptr);

// The normalised 1-D Gaussian taps of the SSIM window (2 radius + 1 values summing to 1); the 2-D window is
// their outer product.
std::vector<double> ssim_gaussian_taps(double sigma, int radius);

}  // namespace temporal
