// PSNR, SSIM and the per-pixel helpers of `compare` (temporal/metrics/metrics.h).
//
// Reductions keep one partial sum per image row (double) and add them in row order afterwards: the result is
// the same whatever the number of threads, which keeps CSV files reproducible.
#include "temporal/metrics/metrics.h"

#include "temporal/core/color.h"
#include "temporal/core/image.h"
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

// FIR filters of the separable Gaussian. With the tap count known at compile time (11 for Wang et al.'s
// window) the tap loop unrolls and the x loop vectorises with one store per output, instead of a
// read-modify-write of the output row per tap.
template <int N>
void fir_row(const double* __restrict in, double* __restrict out, int n, const double* __restrict g) {
  for (int x = 0; x < n; ++x) {
    double s = 0.0;
    for (int k = 0; k < N; ++k) s += g[k] * in[x + k];
    out[x] = s;
  }
}
template <int N>
void fir_column(const double* const* rows, double* __restrict out, int n, const double* __restrict g) {
  const double* r[N];
  for (int k = 0; k < N; ++k) r[k] = rows[k];
  for (int x = 0; x < n; ++x) {
    double s = 0.0;
    for (int k = 0; k < N; ++k) s += g[k] * r[k][x];
    out[x] = s;
  }
}
void fir_row_any(const double* __restrict in, double* __restrict out, int n, const double* g, int taps) {
  std::fill(out, out + n, 0.0);
  for (int k = 0; k < taps; ++k)
    for (int x = 0; x < n; ++x) out[x] += g[k] * in[x + k];
}
void fir_column_any(const double* const* rows, double* __restrict out, int n, const double* g, int taps) {
  std::fill(out, out + n, 0.0);
  for (int k = 0; k < taps; ++k)
    for (int x = 0; x < n; ++x) out[x] += g[k] * rows[k][x];
}

// Weighted: invalid pixels get weight 0 and the window statistics are divided by the remaining weight
// (normalised convolution); unweighted is Wang et al.'s plain Gaussian filtering (weights sum to 1).
//
// Separable and fused: each task takes a band of output rows, runs the horizontal 11-tap pass over the band's
// input rows into a ring of 2r+1 rows per plane (about 5 x 11 x width doubles, cache-resident), and the
// vertical pass straight out of the ring, so no full-size intermediate plane is written to memory.
template <bool Weighted>
SsimResult ssim_impl(const float* test, const float* reference, int width, int height, const std::uint8_t* valid,
                     const float* mask, const SsimOptions& o, float* map) {
  constexpr int kPlanes = Weighted ? 6 : 5;
  const int r = o.radius, taps_n = 2 * r + 1;
  const int ow = width - 2 * r, oh = height - 2 * r;  // window centres ("valid" filtering)
  const std::size_t row_len = std::size_t(ow);
  const std::vector<double> g = ssim_gaussian_taps(o.sigma, r);
  const double c1 = (o.k1 * o.peak) * (o.k1 * o.peak);
  const double c2 = (o.k2 * o.peak) * (o.k2 * o.peak);
  struct Row {
    double sum = 0, sum_in = 0;
    std::size_t n = 0, n_in = 0;
  };
  if (map) std::fill(map, map + std::size_t(width) * std::size_t(height), 0.0f);
  std::vector<Row> rows(std::size_t(std::max(oh, 0)));

  parallel_rows(
      oh,
      [&](int y0, int y1) {
        std::vector<double> prod(std::size_t(width) * kPlanes);
        std::vector<double> ring(std::size_t(taps_n) * row_len * kPlanes);
        std::vector<double> acc(row_len * kPlanes);
        std::vector<double> srow(row_len);
        std::vector<const double*> column(static_cast<std::size_t>(taps_n));
        auto ring_row = [&](int q, int y) { return ring.data() + (std::size_t(q) * std::size_t(taps_n) + std::size_t(y % taps_n)) * row_len; };

        // Horizontal pass of input row y into the ring: products, then the FIR (tap-outer: unit stride).
        auto horizontal = [&](int y) {
          const std::size_t o_in = std::size_t(y) * std::size_t(width);
          const float* xr = test + o_in;
          const float* yr = reference + o_in;
          double* p[6];
          for (int q = 0; q < kPlanes; ++q) p[q] = prod.data() + std::size_t(q) * std::size_t(width);
          for (int x = 0; x < width; ++x) {
            double a = xr[x], b = yr[x], w = 1.0;
            if constexpr (Weighted) {
              w = valid[o_in + std::size_t(x)] ? 1.0 : 0.0;
              a = w != 0.0 ? a : 0.0;
              b = w != 0.0 ? b : 0.0;
              p[5][x] = w;
            }
            p[0][x] = a;
            p[1][x] = b;
            p[2][x] = a * a;
            p[3][x] = b * b;
            p[4][x] = a * b;
          }
          for (int q = 0; q < kPlanes; ++q) {
            if (taps_n == 11) fir_row<11>(p[q], ring_row(q, y), ow, g.data());
            else fir_row_any(p[q], ring_row(q, y), ow, g.data(), taps_n);
          }
        };

        for (int y = y0; y < y0 + 2 * r; ++y) horizontal(y);
        for (int yo = y0; yo < y1; ++yo) {
          horizontal(yo + 2 * r);
          // Vertical pass: window sums of the five (six) products for every centre of output row yo.
          for (int q = 0; q < kPlanes; ++q) {
            for (int k = 0; k < taps_n; ++k) column[std::size_t(k)] = ring_row(q, yo + k);
            double* out = acc.data() + std::size_t(q) * row_len;
            if (taps_n == 11) fir_column<11>(column.data(), out, ow, g.data());
            else fir_column_any(column.data(), out, ow, g.data(), taps_n);
          }
          // Wang et al. eq. 13 for the whole row (branch-free, vectorises), then the sums over kept windows.
          // Window sums are in double: E[x^2] - E[x]^2 cancels, and float sums moved SSIM by ~1e-4 even on
          // [0,1] data (C2 = 9e-4 is small against the float rounding of E[x^2] ~ 0.3).
          const double* __restrict a0 = acc.data();
          const double* __restrict a1 = a0 + row_len;
          const double* __restrict a2 = a1 + row_len;
          const double* __restrict a3 = a2 + row_len;
          const double* __restrict a4 = a3 + row_len;
          const double* __restrict a5 = Weighted ? a4 + row_len : nullptr;
          for (int x = 0; x < ow; ++x) {
            double inv = 1.0;
            if constexpr (Weighted) inv = a5[x] > 1e-12 ? 1.0 / a5[x] : 0.0;
            const double mx = a0[x] * inv, my = a1[x] * inv;
            const double sxx = a2[x] * inv - mx * mx;
            const double syy = a3[x] * inv - my * my;
            const double sxy = a4[x] * inv - mx * my;
            srow[std::size_t(x)] =
                ((2.0 * mx * my + c1) * (2.0 * sxy + c2)) / ((mx * mx + my * my + c1) * (sxx + syy + c2));
          }
          Row row;
          const std::size_t centre0 = std::size_t(yo + r) * std::size_t(width) + std::size_t(r);
          for (int x = 0; x < ow; ++x) {
            const std::size_t centre = centre0 + std::size_t(x);
            if constexpr (Weighted) {
              if (!valid[centre] || !(a5[x] > 1e-12)) continue;
            }
            const double v = srow[std::size_t(x)];
            row.sum += v;
            ++row.n;
            if (mask && mask[centre] > 0.5f) {
              row.sum_in += v;
              ++row.n_in;
            }
            if (map) map[centre] = float(1.0 - v);
          }
          rows[std::size_t(yo)] = row;
        }
      },
      32);  // 32 output rows per task: the 2r extra input rows of each band cost ~30% more horizontal work

  SsimResult result;
  double sum = 0, sum_in = 0;
  for (const auto& row : rows) {
    sum += row.sum;
    sum_in += row.sum_in;
    result.windows += row.n;
    result.windows_inside += row.n_in;
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  result.mean = result.windows ? sum / double(result.windows) : nan;
  if (mask) {
    result.windows_outside = result.windows - result.windows_inside;
    result.mean_inside = result.windows_inside ? sum_in / double(result.windows_inside) : nan;
    result.mean_outside = result.windows_outside ? (sum - sum_in) / double(result.windows_outside) : nan;
  }
  return result;
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
  if (all_valid)
    return ssim_impl<false>(test, reference, width, height, valid, mask, options, map);
  return ssim_impl<true>(test, reference, width, height, valid, mask, options, map);
}

}  // namespace temporal
