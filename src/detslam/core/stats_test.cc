#include "detslam/core/stats.h"

#include <gtest/gtest.h>

#include <cmath>

namespace detslam {
namespace {

TEST(ErrorStats, HandComputedOddAndEvenCounts) {
  // {3, 1, 2}: mean 2, median 2, rmse sqrt(14/3), population std sqrt(2/3).
  const ErrorStats odd = ComputeErrorStats({3, 1, 2});
  EXPECT_EQ(odd.count, 3u);
  EXPECT_DOUBLE_EQ(odd.mean, 2.0);
  EXPECT_DOUBLE_EQ(odd.median, 2.0);
  EXPECT_DOUBLE_EQ(odd.rmse, std::sqrt(14.0 / 3.0));
  EXPECT_DOUBLE_EQ(odd.std, std::sqrt(2.0 / 3.0));
  EXPECT_DOUBLE_EQ(odd.min, 1.0);
  EXPECT_DOUBLE_EQ(odd.max, 3.0);
  // Even count: median is the mean of the two middle values (numpy.median).
  const ErrorStats even = ComputeErrorStats({4, 1, 10, 2});
  EXPECT_DOUBLE_EQ(even.median, 3.0);
  EXPECT_DOUBLE_EQ(even.std,
                   std::sqrt((3.25 * 3.25 + 0.25 * 0.25 + 2.25 * 2.25 + 5.75 * 5.75) / 4));
}

TEST(ErrorStats, EmptyAndScaled) {
  const ErrorStats empty = ComputeErrorStats({});
  EXPECT_EQ(empty.count, 0u);
  EXPECT_EQ(empty.rmse, 0.0);
  const ErrorStats s = ScaleErrorStats(ComputeErrorStats({1, 3}), 0.5);
  EXPECT_EQ(s.count, 2u);
  EXPECT_DOUBLE_EQ(s.mean, 1.0);
  EXPECT_DOUBLE_EQ(s.max, 1.5);
  EXPECT_DOUBLE_EQ(s.std, 0.5);
}

TEST(Percentile, InterpolatesBetweenRanksLikeNumpy) {
  // numpy.percentile([1, 2, 3, 4], q) for q = 0, 50, 99, 100: 1, 2.5, 3.97, 4.
  const std::vector<double> v = {4, 1, 3, 2};
  EXPECT_DOUBLE_EQ(Percentile(v, 0), 1.0);
  EXPECT_DOUBLE_EQ(Percentile(v, 50), 2.5);
  EXPECT_NEAR(Percentile(v, 99), 3.97, 1e-12);
  EXPECT_DOUBLE_EQ(Percentile(v, 100), 4.0);
  EXPECT_DOUBLE_EQ(Percentile({7}, 99), 7.0);
  EXPECT_EQ(Percentile({}, 50), 0.0);
}

}  // namespace
}  // namespace detslam
