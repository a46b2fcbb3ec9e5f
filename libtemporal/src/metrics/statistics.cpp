// Moving-block bootstrap intervals (temporal/metrics/statistics.h).
#include "temporal/metrics/statistics.h"

#include <algorithm>
#include <cmath>
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
  const std::size_t block =
      o.block > 0 ? std::size_t(o.block) : std::max<std::size_t>(1, std::size_t(std::lround(std::cbrt(double(n)))));
  const std::size_t blocks = (n + block - 1) / block;
  std::mt19937_64 rng(o.seed);
  std::uniform_int_distribution<std::size_t> start(0, n - 1);
  std::vector<double> means(std::size_t(std::max(1, o.resamples)));
  for (auto& m : means) {
    // ceil(n / L) circular blocks, truncated to n values.
    double sum = 0.0;
    std::size_t taken = 0;
    for (std::size_t b = 0; b < blocks; ++b) {
      const std::size_t s = start(rng);
      for (std::size_t k = 0; k < block && taken < n; ++k, ++taken) sum += v[(s + k) % n];
    }
    m = sum / double(n);
  }
  std::sort(means.begin(), means.end());
  const double tail = (1.0 - o.level) / 2.0;
  r.ci = {percentile(means, tail), percentile(means, 1.0 - tail)};
  return r;
}

}  // namespace

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
