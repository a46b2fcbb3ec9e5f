// Bootstrap intervals (temporal/metrics/statistics.h): hand-checkable cases.
#include "temporal/metrics/statistics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace {

using namespace temporal;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

TEST(Bootstrap, AConstantSeriesHasAZeroWidthInterval) {
  const std::vector<double> v(48, 31.5);
  const auto m = bootstrap_mean(v);
  EXPECT_EQ(m.count, 48u);
  EXPECT_EQ(m.mean, 31.5);
  EXPECT_EQ(m.ci.low, 31.5);
  EXPECT_EQ(m.ci.high, 31.5);
}

TEST(Bootstrap, MissingValuesAreLeftOutAndInfinitiesKept) {
  const std::vector<double> v = {1.0, kNaN, 3.0, kNaN};
  const auto m = bootstrap_mean(v);
  EXPECT_EQ(m.count, 2u);
  EXPECT_EQ(m.mean, 2.0);
  EXPECT_GE(m.ci.low, 1.0);
  EXPECT_LE(m.ci.high, 3.0);
  const std::vector<double> w = {30.0, kInf, 30.0};
  const auto mi = bootstrap_mean(w);
  EXPECT_EQ(mi.infinite, 1u);
  EXPECT_TRUE(std::isinf(mi.mean));
  EXPECT_TRUE(std::isinf(mi.ci.high));
  const auto empty = bootstrap_mean(std::vector<double>{kNaN});
  EXPECT_EQ(empty.count, 0u);
  EXPECT_TRUE(std::isnan(empty.mean));
}

TEST(Bootstrap, IntervalCoversTheMeanOfIndependentNoiseAtAboutTheRightWidth) {
  // 400 independent N(0, 1) values: the mean's standard error is 1 / 20, so a 95 % interval is about
  // +-1.96 / 20 = +-0.098 wide around the sample mean (block bootstrap of iid data: the same to a few %).
  std::mt19937 rng(3);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::vector<double> v(400);
  for (auto& x : v) x = n01(rng);
  const auto m = bootstrap_mean(v);
  EXPECT_LT(m.ci.low, m.mean);
  EXPECT_GT(m.ci.high, m.mean);
  const double half = (m.ci.high - m.ci.low) / 2.0;
  EXPECT_NEAR(half, 0.098, 0.025);
  // The same series gives the same interval (fixed seed).
  const auto again = bootstrap_mean(v);
  EXPECT_EQ(again.ci.low, m.ci.low);
  EXPECT_EQ(again.ci.high, m.ci.high);
}

TEST(Bootstrap, BlocksWidenTheIntervalOfCorrelatedFrames) {
  // A slowly drifting series (strongly autocorrelated): resampling single frames understates the uncertainty
  // of its mean; blocks of consecutive frames do not.
  std::vector<double> v(64);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = std::sin(double(i) / 8.0);
  BootstrapOptions single;
  single.block = 1;
  const auto a = bootstrap_mean(v, single), b = bootstrap_mean(v);  // default block round(64^(1/3)) = 4
  EXPECT_GT(b.ci.high - b.ci.low, 1.5 * (a.ci.high - a.ci.low));
}

TEST(Bootstrap, PairedDifferences) {
  const std::vector<double> a = {30, 31, 32, 33, kInf, kNaN}, b = {29, 30, 31, 32, kInf, 5};
  const auto d = bootstrap_paired_difference(a, b);
  EXPECT_EQ(d.count, 5u);     // the frame where a has no value is left out
  EXPECT_EQ(d.mean, 0.8);     // (1 + 1 + 1 + 1 + 0) / 5: two perfect frames tie
  EXPECT_GE(d.ci.low, 0.0);
  EXPECT_LE(d.ci.high, 1.0);
  const auto same = bootstrap_paired_difference(a, a);
  EXPECT_EQ(same.mean, 0.0);
  EXPECT_EQ(same.ci.low, 0.0);
  EXPECT_EQ(same.ci.high, 0.0);
}

}  // namespace
