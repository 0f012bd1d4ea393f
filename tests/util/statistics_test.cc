#include "util/statistics.h"

#include <gtest/gtest.h>

#include <random>

namespace puzzlecal {
namespace {

TEST(StatisticsTest, MedianOfOddAndEvenCountsAndEmpty) {
  EXPECT_EQ(Median({3, 1, 2}), 2);
  EXPECT_EQ(Median({4, 1, 3, 2}), 3);  // the upper median
  EXPECT_EQ(Median({}), 0);
}

TEST(StatisticsTest, QuantileInterpolatesBetweenOrderStatistics) {
  const std::vector<double> values = {10, 0, 30, 20, 40};
  EXPECT_DOUBLE_EQ(Quantile(values, 0.0), 0);
  EXPECT_DOUBLE_EQ(Quantile(values, 1.0), 40);
  EXPECT_DOUBLE_EQ(Quantile(values, 0.5), 20);
  EXPECT_DOUBLE_EQ(Quantile(values, 0.125), 5);
  EXPECT_DOUBLE_EQ(Quantile(values, 2.0), 40);  // clamped
  EXPECT_EQ(Quantile({}, 0.5), 0);
}

TEST(StatisticsTest, MadSigmaEstimatesGaussianSigmaAndIgnoresGrossErrors) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(5.0, 0.3);
  std::vector<double> values(20000);
  for (double& v : values) v = noise(rng);
  EXPECT_NEAR(MedianAbsoluteDeviationSigma(values), 0.3, 0.01);
  // 10 % gross errors move the estimate by little.
  for (size_t i = 0; i < values.size(); i += 10) values[i] = 1e3;
  EXPECT_NEAR(MedianAbsoluteDeviationSigma(values), 0.3, 0.05);
}

TEST(StatisticsTest, EvenlySpreadIndicesSampleEvenlyOrTakeAll) {
  EXPECT_EQ(EvenlySpreadIndices(10, 5), (std::vector<size_t>{0, 2, 4, 6, 8}));
  EXPECT_EQ(EvenlySpreadIndices(7, 3), (std::vector<size_t>{0, 2, 4}));
  EXPECT_EQ(EvenlySpreadIndices(3, 8), (std::vector<size_t>{0, 1, 2}));
  EXPECT_TRUE(EvenlySpreadIndices(5, 0).empty());
  EXPECT_TRUE(EvenlySpreadIndices(0, 4).empty());
}

}  // namespace
}  // namespace puzzlecal
