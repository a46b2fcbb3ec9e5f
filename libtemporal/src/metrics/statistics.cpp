// Moving-block bootstrap intervals (temporal/metrics/statistics.h).
#include "temporal/metrics/statistics.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>

namespace temporal {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double mean_of(const std::vector<double>& v) {
  double sum = 0.0;
  for (double x : v) sum += x;
  return sum / double(v.size());
}

// Percentile of sorted values (linear interpolation between order statistics).
double percentile(const std::vector<double>& sorted, double p) {
  if (sorted.size() == 1) return sorted.front();
  const double pos = p * double(sorted.size() - 1);
  const std::size_t i = std::size_t(std::floor(pos));
  const double f = pos - double(i);
  if (i + 1 >= sorted.size()) return sorted.back();
  if (f == 0.0 || sorted[i] == sorted[i + 1]) return sorted[i];  // exact, and no inf - inf
  return sorted[i] + f * (sorted[i + 1] - sorted[i]);
}

// The resampling both bootstraps share: o.resamples resamples of n frames, each ceil(n / L) circular blocks of L
// consecutive frame indices at uniformly drawn starts, truncated to n (L = o.block, else round(n^(1/3)), at least 1).
// For every resample, take(t, i) receives its t-th index i (t = 0 .. n-1) and done() ends it; the same seed draws
// the same blocks for both bootstraps.
template <typename Take, typename Done>
void resample_blocks(std::size_t n, const BootstrapOptions& o, Take&& take, Done&& done) {
  const std::size_t block =
      o.block > 0 ? std::size_t(o.block) : std::max<std::size_t>(1, std::size_t(std::lround(std::cbrt(double(n)))));
  const std::size_t blocks = (n + block - 1) / block;
  std::mt19937_64 rng(o.seed);
  std::uniform_int_distribution<std::size_t> start(0, n - 1);
  for (int r = 0; r < std::max(1, o.resamples); ++r) {
    std::size_t taken = 0;
    for (std::size_t b = 0; b < blocks; ++b) {
      const std::size_t s = start(rng);
      for (std::size_t k = 0; k < block && taken < n; ++k, ++taken) take(taken, (s + k) % n);
    }
    done();
  }
}

MeanInterval block_bootstrap(const std::vector<double>& v, const BootstrapOptions& o) {
  MeanInterval r;
  r.count = v.size();
  for (double x : v) r.infinite += std::isinf(x) ? 1 : 0;
  if (v.empty()) {
    r.mean = kNaN;
    r.ci = {kNaN, kNaN};
    return r;
  }
  r.mean = mean_of(v);
  const std::size_t n = v.size();
  std::vector<double> means;
  means.reserve(std::size_t(std::max(1, o.resamples)));
  double sum = 0.0;
  resample_blocks(n, o, [&](std::size_t, std::size_t i) { sum += v[i]; }, [&] {
    means.push_back(sum / double(n));
    sum = 0.0;
  });
  std::sort(means.begin(), means.end());
  const double tail = (1.0 - o.level) / 2.0;
  r.ci = {percentile(means, tail), percentile(means, 1.0 - tail)};
  return r;
}

// The moving-block bootstrap of any statistic of n frames: `stat` gets the frame indices of one resample (circular
// blocks as in block_bootstrap, so the same seed draws the same blocks).
MeanInterval block_bootstrap_statistic(std::size_t n, const BootstrapOptions& o,
                                       const std::function<double(const std::vector<std::size_t>&)>& stat) {
  MeanInterval r;
  r.count = n;
  if (n == 0) {
    r.mean = kNaN;
    r.ci = {kNaN, kNaN};
    return r;
  }
  std::vector<std::size_t> idx(n);
  for (std::size_t i = 0; i < n; ++i) idx[i] = i;
  r.mean = stat(idx);
  std::vector<double> values;
  values.reserve(std::size_t(std::max(1, o.resamples)));
  resample_blocks(n, o, [&](std::size_t t, std::size_t i) { idx[t] = i; }, [&] { values.push_back(stat(idx)); });
  std::sort(values.begin(), values.end());
  const double tail = (1.0 - o.level) / 2.0;
  r.ci = {percentile(values, tail), percentile(values, 1.0 - tail)};
  return r;
}

// -10 log10(sum w e / sum w) over the frames `idx` (e = normalised squared error 10^(-p/10)).
double pooled_of(const std::vector<double>& e, const std::vector<double>& w, const std::vector<std::size_t>& idx) {
  double num = 0.0, den = 0.0;
  for (const std::size_t i : idx) {
    num += w[i] * e[i];
    den += w[i];
  }
  if (!(den > 0.0)) return kNaN;
  if (std::isinf(num)) return -std::numeric_limits<double>::infinity();
  return num > 0.0 ? -10.0 * std::log10(num / den) : std::numeric_limits<double>::infinity();
}

// 10^(-p/10): +inf dB -> 0, -inf dB -> +inf.
double normalised_error(double psnr) { return std::pow(10.0, -psnr / 10.0); }

}  // namespace

double pooled_psnr(std::span<const double> psnr, std::span<const double> weight) {
  std::vector<double> e, w;
  std::vector<std::size_t> idx;
  for (std::size_t i = 0; i < std::min(psnr.size(), weight.size()); ++i) {
    if (std::isnan(psnr[i]) || !(weight[i] > 0.0)) continue;
    idx.push_back(e.size());
    e.push_back(normalised_error(psnr[i]));
    w.push_back(weight[i]);
  }
  return pooled_of(e, w, idx);
}

MeanInterval bootstrap_pooled_psnr(std::span<const double> psnr, std::span<const double> weight,
                                   const BootstrapOptions& options) {
  std::vector<double> e, w;
  for (std::size_t i = 0; i < std::min(psnr.size(), weight.size()); ++i) {
    if (std::isnan(psnr[i]) || !(weight[i] > 0.0)) continue;
    e.push_back(normalised_error(psnr[i]));
    w.push_back(weight[i]);
  }
  return block_bootstrap_statistic(e.size(), options, [&](const std::vector<std::size_t>& idx) { return pooled_of(e, w, idx); });
}

MeanInterval bootstrap_pooled_psnr_difference(std::span<const double> psnr_a, std::span<const double> weight_a,
                                              std::span<const double> psnr_b, std::span<const double> weight_b,
                                              const BootstrapOptions& options) {
  std::vector<double> ea, wa, eb, wb;
  const std::size_t n = std::min({psnr_a.size(), weight_a.size(), psnr_b.size(), weight_b.size()});
  for (std::size_t i = 0; i < n; ++i) {
    if (std::isnan(psnr_a[i]) || std::isnan(psnr_b[i]) || !(weight_a[i] > 0.0) || !(weight_b[i] > 0.0)) continue;
    ea.push_back(normalised_error(psnr_a[i]));
    wa.push_back(weight_a[i]);
    eb.push_back(normalised_error(psnr_b[i]));
    wb.push_back(weight_b[i]);
  }
  return block_bootstrap_statistic(ea.size(), options, [&](const std::vector<std::size_t>& idx) {
    const double a = pooled_of(ea, wa, idx), b = pooled_of(eb, wb, idx);
    if (std::isinf(a) && std::isinf(b) && (a > 0) == (b > 0)) return 0.0;  // both exact (or both broken): a tie
    return a - b;
  });
}

MeanInterval bootstrap_mean(std::span<const double> series, const BootstrapOptions& options) {
  std::vector<double> v;
  for (double x : series)
    if (!std::isnan(x)) v.push_back(x);
  return block_bootstrap(v, options);
}

MeanInterval bootstrap_paired_difference(std::span<const double> a, std::span<const double> b,
                                         const BootstrapOptions& options) {
  std::vector<double> d;
  const std::size_t n = std::min(a.size(), b.size());
  for (std::size_t i = 0; i < n; ++i) {
    if (std::isnan(a[i]) || std::isnan(b[i])) continue;
    const bool tie = std::isinf(a[i]) && std::isinf(b[i]) && (a[i] > 0) == (b[i] > 0);
    d.push_back(tie ? 0.0 : a[i] - b[i]);
  }
  return block_bootstrap(d, options);
}

}  // namespace temporal
