#include "detslam/dynamic/geometric_check.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace detslam {
namespace {

constexpr auto S = KeypointLabel::kStatic;
constexpr auto G = KeypointLabel::kGeometric;
constexpr auto M = KeypointLabel::kDynamicMask;

TEST(GeometricCheckTest, Median) {
  EXPECT_DOUBLE_EQ(Median({}), 0.0);
  EXPECT_DOUBLE_EQ(Median({3.0}), 3.0);
  EXPECT_DOUBLE_EQ(Median({5.0, 1.0, 3.0}), 3.0);
  EXPECT_DOUBLE_EQ(Median({4.0, 1.0, 3.0, 10.0}), 3.5);
}

// Sorted static residuals: 0.9 0.9 1.0 1.0 1.0 1.0 1.0 1.1 1.1 8.0 -> median 1.0; deviations
// 0 0 0 0 0 0.1 0.1 0.1 0.1 7.0 -> MAD 0.05; median + 3 * 1.4826 * 0.05 = 1.22239.
const std::vector<double> kResiduals = {0.9, 1.0, 1.0, 1.1, 1.0, 0.9, 1.1, 1.0, 1.0, 8.0};

TEST(GeometricCheckTest, HandComputedThresholdAndFloor) {
  GeometricCheckOptions options;
  options.min_threshold = 0.0;
  std::vector<double> residuals = kResiduals;
  residuals.push_back(1.5);
  // sorted 0.9 0.9 1.0 1.0 1.0 1.0 1.0 1.1 1.1 1.5 8.0 -> median 1.0; deviations
  // 0 0 0 0 0 0.1 0.1 0.1 0.1 0.5 7.0 -> MAD 0.1 (6th of 11) -> threshold 1.44478.
  std::vector<KeypointLabel> labels(residuals.size(), S);
  GeometricCheckResult result = FlagGeometricOutliers(residuals, options, &labels);
  EXPECT_EQ(result.samples, 11);
  EXPECT_DOUBLE_EQ(result.median, 1.0);
  EXPECT_NEAR(result.mad, 0.1, 1e-12);
  EXPECT_NEAR(result.threshold, 1.0 + 3.0 * 1.4826 * 0.1, 1e-12);
  EXPECT_EQ(labels, (std::vector<KeypointLabel>{S, S, S, S, S, S, S, S, S, G, G}));
  EXPECT_EQ(result.flagged, 2);

  labels.assign(kResiduals.size(), S);
  result = FlagGeometricOutliers(kResiduals, options, &labels);
  EXPECT_NEAR(result.mad, 0.05, 1e-12);
  EXPECT_NEAR(result.threshold, 1.0 + 3.0 * 1.4826 * 0.05, 1e-12);
  EXPECT_EQ(labels, (std::vector<KeypointLabel>{S, S, S, S, S, S, S, S, S, G}));

  options.min_threshold = 10.0;  // the floor wins: nothing is that far off
  labels.assign(kResiduals.size(), S);
  result = FlagGeometricOutliers(kResiduals, options, &labels);
  EXPECT_DOUBLE_EQ(result.threshold, 10.0);
  EXPECT_EQ(result.flagged, 0);
  EXPECT_EQ(labels, std::vector<KeypointLabel>(kResiduals.size(), S));
}

TEST(GeometricCheckTest, OnlyStaticKeypointsWithResidualsCountAndChange) {
  GeometricCheckOptions options;
  options.min_threshold = 0.0;
  std::vector<double> residuals = kResiduals;
  std::vector<KeypointLabel> labels(residuals.size(), S);
  // Non-static keypoints and missing residuals neither vote nor change.
  residuals.push_back(50.0);
  labels.push_back(M);
  residuals.push_back(-1.0);
  labels.push_back(S);
  residuals.push_back(std::numeric_limits<double>::quiet_NaN());
  labels.push_back(S);
  const GeometricCheckResult result = FlagGeometricOutliers(residuals, options, &labels);
  EXPECT_EQ(result.samples, 10);
  EXPECT_NEAR(result.threshold, 1.0 + 3.0 * 1.4826 * 0.05, 1e-12);
  EXPECT_EQ(labels, (std::vector<KeypointLabel>{S, S, S, S, S, S, S, S, S, G, M, S, S}));
}

TEST(GeometricCheckTest, TooFewSamplesFlagNothing) {
  GeometricCheckOptions options;
  options.min_samples = 11;
  std::vector<KeypointLabel> labels(kResiduals.size(), S);
  const GeometricCheckResult result = FlagGeometricOutliers(kResiduals, options, &labels);
  EXPECT_EQ(result.flagged, 0);
  EXPECT_TRUE(std::isinf(result.threshold));
  EXPECT_EQ(labels, std::vector<KeypointLabel>(kResiduals.size(), S));
}

TEST(GeometricCheckTest, OptionsCheck) {
  std::string error;
  EXPECT_TRUE(GeometricCheckOptions().Check(&error)) << error;
  GeometricCheckOptions options;
  options.k = 0.0;
  EXPECT_FALSE(options.Check(&error));
  options = GeometricCheckOptions();
  options.min_threshold = -1.0;
  EXPECT_FALSE(options.Check(&error));
  options = GeometricCheckOptions();
  options.min_samples = 0;
  EXPECT_FALSE(options.Check(&error));
}

}  // namespace
}  // namespace detslam
