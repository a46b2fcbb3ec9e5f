// PSNR, SSIM and the per-pixel helpers of `compare` (temporal/metrics/metrics.h).
//
// Reductions keep one partial sum per image row (double) and add them in row order afterwards: the result is
// the same whatever the number of threads, which keeps CSV files reproducible.
#include "temporal/metrics/metrics.h"

#include "temporal/core/color.h"
#include "temporal/core/image.h"
#include "temporal/core/isa.h"
#include "temporal/core/parallel.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace temporal {
namespace {

template <typename Partial, typename RowBody>
std::vector<Partial> row_partials(int height, RowBody&& body) {
  std::vector<Partial> partials(std::size_t(std::max(height, 0)));
  parallel_rows(height, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y) body(y, partials[std::size_t(y)]);
  });
  return partials;
}

}  // namespace

std::vector<std::string> compared_channels(const Image& image, std::string_view layer) {
  auto names = select_layers(image, layer, {});
  return names ? std::move(*names) : std::vector<std::string>();
}

void luminance_plane(std::span<const float* const> channels, std::size_t count, float* out) {
  const std::size_t n = channels.size();
  parallel_chunks(count, [&](std::size_t b, std::size_t e) {
    if (n == 3) {
      const float* __restrict r = channels[0];
      const float* __restrict g = channels[1];
      const float* __restrict bl = channels[2];
      for (std::size_t i = b; i < e; ++i) out[i] = luminance(r[i], g[i], bl[i]);
    } else if (n == 1) {
      std::copy(channels[0] + b, channels[0] + e, out + b);
    } else {
      const float w = n ? 1.0f / float(n) : 0.0f;
      std::fill(out + b, out + e, 0.0f);
      for (const float* c : channels)
        for (std::size_t i = b; i < e; ++i) out[i] += w * c[i];
    }
  });
}

std::size_t finite_mask(std::span<const float* const> a, std::span<const float* const> b, std::size_t count,
                        std::uint8_t* valid) {
  struct Count {
    std::size_t invalid = 0;
  };
  constexpr std::size_t kChunk = 8192;
  const std::size_t chunks = (count + kChunk - 1) / kChunk;
  std::vector<Count> partial(chunks);
  parallel_chunks(
      chunks,
      [&](std::size_t c0, std::size_t c1) {
        for (std::size_t c = c0; c < c1; ++c) {
          const std::size_t b0 = c * kChunk, b1 = std::min(count, b0 + kChunk);
          // x * 0 is 0 for every finite x and NaN for NaN and +-Inf (not folded away without -ffast-math), so
          // one running sum per pixel over the planes flags every non-finite value; the loops vectorise.
          float zero[kChunk];
          const std::size_t len = b1 - b0;
          std::fill(zero, zero + len, 0.0f);
          auto add = [&](const float* __restrict p) {
            for (std::size_t i = 0; i < len; ++i) zero[i] += p[b0 + i] * 0.0f;
          };
          for (const float* p : a) add(p);
          for (const float* p : b) add(p);
          std::size_t invalid = 0;
          for (std::size_t i = 0; i < len; ++i) {
            const std::uint8_t ok = zero[i] == 0.0f;
            valid[b0 + i] = ok;
            invalid += std::size_t(1 - ok);
          }
          partial[c].invalid = invalid;
        }
      },
      1);
  std::size_t total = 0;
  for (const auto& p : partial) total += p.invalid;
  return total;
}

SquaredErrorSplit squared_error(std::span<const float* const> test, std::span<const float* const> reference,
                                int width, int height, const std::uint8_t* valid, const float* mask) {
  const std::size_t channels = std::min(test.size(), reference.size());
  struct Row {
    double all = 0, inside = 0;
    std::size_t n_all = 0, n_inside = 0;
  };
  auto rows = row_partials<Row>(height, [&](int y, Row& row) {
    const std::size_t o = std::size_t(y) * std::size_t(width);
    // Branch-free: invalid pixels contribute 0. Sums run in 16 float lanes per row (vectorises without
    // -ffast-math, since the lanes fix the order); lanes and rows add up in double.
    constexpr int kLanes = 16;
    float all[kLanes] = {}, inside[kLanes] = {};
    std::size_t n_all = 0, n_inside = 0;
    auto pixel = [&](std::size_t i, float& s_all, float& s_in) {
      float s = 0.0f;
      for (std::size_t c = 0; c < channels; ++c) {
        const float d = test[c][i] - reference[c][i];
        s += d * d;
      }
      s = valid[i] ? s : 0.0f;
      const bool in = mask && mask[i] > 0.5f && valid[i];
      s_all += s;
      s_in += in ? s : 0.0f;
      n_all += valid[i];
      n_inside += in;
    };
    int x = 0;
    for (; x + kLanes <= width; x += kLanes)
      for (int l = 0; l < kLanes; ++l) pixel(o + std::size_t(x + l), all[l], inside[l]);
    for (; x < width; ++x) pixel(o + std::size_t(x), all[0], inside[0]);
    double sa = 0.0, si = 0.0;
    for (int l = 0; l < kLanes; ++l) {
      sa += all[l];
      si += inside[l];
    }
    row = {sa, si, n_all, n_inside};
  });
  SquaredErrorSplit out;
  for (const auto& r : rows) {
    out.all.sum += r.all;
    out.all.samples += r.n_all * channels;
    out.inside.sum += r.inside;
    out.inside.samples += r.n_inside * channels;
  }
  if (mask) {
    out.outside.sum = std::max(0.0, out.all.sum - out.inside.sum);
    out.outside.samples = out.all.samples - out.inside.samples;
  }
  return out;
}

double psnr_db(const SquaredError& error, double peak) {
  if (error.samples == 0) return std::numeric_limits<double>::quiet_NaN();
  const double mse = error.mean();
  if (mse <= 0.0) return std::numeric_limits<double>::infinity();
  return 10.0 * std::log10(peak * peak / mse);
}

float idiff_peak(std::span<const float* const> planes, std::size_t count) {
  float peak = 1.0f;
  for (const float* p : planes)
    for (std::size_t i = 0; i < count; ++i)
      if (std::fabs(p[i]) <= std::numeric_limits<float>::max()) peak = std::max(peak, p[i]);
  return peak;
}

// ---------------------------------------------------------------------------------------------------------
// SSIM

std::vector<double> ssim_gaussian_taps(double sigma, int radius) {
  std::vector<double> taps(std::size_t(2 * radius + 1));
  double sum = 0.0;
  for (int k = -radius; k <= radius; ++k) {
    taps[std::size_t(k + radius)] = std::exp(-double(k * k) / (2.0 * sigma * sigma));
    sum += taps[std::size_t(k + radius)];
  }
  for (auto& t : taps) t /= sum;
  return taps;
}

namespace {

// The SSIM kernel copies, one per instruction set (temporal/core/isa.h); they differ only in FMA contraction of
// the double-precision filters (v3 and v4 contract, v2 cannot), a few 1e-16 relative.
#define TEMPORAL_ISA_FILE "ssim_kernels.inc"
#include "temporal/core/isa_copies.inc"

using SsimKernel = SsimResult (*)(const float*, const float*, int, int, const std::uint8_t*, const float*,
                                  const SsimOptions&, float*);

SsimKernel ssim_kernel(bool weighted) {
#if TEMPORAL_ISA_DISPATCH
  static constexpr SsimKernel table[3][2] = {{v2::ssim_impl<false>, v2::ssim_impl<true>},
                                             {v3::ssim_impl<false>, v3::ssim_impl<true>},
                                             {v4::ssim_impl<false>, v4::ssim_impl<true>}};
  return table[int(isa::active())][weighted ? 1 : 0];  // Level::V2, V3, V4 are 0, 1, 2
#else
  return weighted ? native::ssim_impl<true> : native::ssim_impl<false>;
#endif
}

}  // namespace

Expected<SsimResult> ssim(const float* test, const float* reference, int width, int height,
                          const std::uint8_t* valid, const float* mask, const SsimOptions& options, float* map) {
  const int window = 2 * options.radius + 1;
  if (options.radius < 0 || !(options.sigma > 0.0) || !(options.peak > 0.0))
    return Error::usage("SSIM needs a window radius >= 0, sigma > 0 and a peak > 0");
  if (width < window || height < window)
    return Error::input({}, "image is " + std::to_string(width) + "x" + std::to_string(height) +
                                ", smaller than the " + std::to_string(window) + "x" + std::to_string(window) +
                                " SSIM window: compare images of at least that size");
  bool all_valid = true;
  if (valid) {
    const std::size_t n = std::size_t(width) * std::size_t(height);
    all_valid = std::find(valid, valid + n, std::uint8_t(0)) == valid + n;
  }
  return ssim_kernel(!all_valid)(test, reference, width, height, valid, mask, options, map);
}

}  // namespace temporal
