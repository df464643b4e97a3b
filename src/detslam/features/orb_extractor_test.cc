#include "detslam/features/orb_extractor.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "detslam/core/check.h"
#include "detslam/features/orb_pattern.h"
#include "detslam/features/texture_for_test.h"

namespace detslam {
namespace {

using detslam::testing::MakeTexture;

struct Extraction {
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
};

Extraction Extract(const cv::Mat& image, const cv::Mat& mask = cv::Mat(),
                   const OrbOptions& options = OrbOptions()) {
  Extraction e;
  OrbExtractor(options).Extract(image, mask, &e.keypoints, &e.descriptors);
  return e;
}

TEST(OrbOptionsTest, CheckRejectsBadValues) {
  std::string error;
  EXPECT_TRUE(OrbOptions().Check(&error)) << error;
  OrbOptions bad;
  bad.scale_factor = 1.0;
  EXPECT_FALSE(bad.Check(&error));
  EXPECT_NE(error.find("scale_factor"), std::string::npos);
  bad = OrbOptions();
  bad.ini_th_fast = 5;  // below min_th_fast
  EXPECT_FALSE(bad.Check(&error));
  EXPECT_THROW(OrbExtractor{bad}, InputError);
}

TEST(OrbExtractorTest, RejectsWrongInput) {
  const OrbExtractor extractor{OrbOptions()};
  std::vector<cv::KeyPoint> kps;
  cv::Mat desc;
  EXPECT_THROW(extractor.Extract(cv::Mat(), cv::Mat(), &kps, &desc), InputError);
  EXPECT_THROW(extractor.Extract(cv::Mat(480, 640, CV_8UC3), cv::Mat(), &kps, &desc), InputError);
  EXPECT_THROW(extractor.Extract(cv::Mat(480, 640, CV_8UC1, cv::Scalar(0)),
                                 cv::Mat(10, 10, CV_8UC1), &kps, &desc),
               InputError);
}

TEST(OrbExtractorTest, ScaleTablesAndLevelTargets) {
  const OrbExtractor extractor{OrbOptions()};
  ASSERT_EQ(extractor.num_levels(), 8);
  for (int l = 0; l < 8; ++l) {
    EXPECT_NEAR(extractor.scale_factors()[l], std::pow(1.2, l), 1e-12);
    EXPECT_NEAR(extractor.level_sigma2()[l], std::pow(1.44, l), 1e-12);
    EXPECT_NEAR(extractor.inv_level_sigma2()[l] * extractor.level_sigma2()[l], 1.0, 1e-12);
  }
  const std::vector<int>& n = extractor.features_per_level();
  EXPECT_EQ(std::accumulate(n.begin(), n.end(), 0), 1000);
  // n0 = N (1 - f) / (1 - f^L), f = 1 / 1.2.
  const double f = 1.0 / 1.2;
  EXPECT_NEAR(n[0], 1000 * (1 - f) / (1 - std::pow(f, 8)), 0.5);
  for (int l = 1; l + 1 < 8; ++l) EXPECT_NEAR(n[l], n[0] * std::pow(f, l), 1.0) << l;
}

TEST(OrbPatternTest, PairsInsidePatchDistinctAndSpread) {
  const auto& pattern = OrbPattern();
  double sum = 0, sum2 = 0;
  for (const BriefPair& p : pattern) {
    for (int v : {p.x1, p.y1, p.x2, p.y2}) {
      EXPECT_LE(std::abs(v), kOrbPatternHalfSize);
      sum += v;
      sum2 += v * v;
    }
    EXPECT_FALSE(p.x1 == p.x2 && p.y1 == p.y2);
  }
  const double mean = sum / 1024, sd = std::sqrt(sum2 / 1024 - mean * mean);
  EXPECT_NEAR(mean, 0.0, 1.0);
  EXPECT_NEAR(sd, 31.0 / 5.0, 1.0);  // Gaussian sigma 6.2, slightly narrowed by the clipping
}

TEST(OrbExtractorTest, KeypointsSpreadOverImageAndFieldsValid) {
  const cv::Mat image = MakeTexture(640, 480, 1);
  const Extraction e = Extract(image);
  ASSERT_EQ(e.descriptors.rows, static_cast<int>(e.keypoints.size()));
  EXPECT_EQ(e.descriptors.cols, 32);
  EXPECT_EQ(e.descriptors.type(), CV_8UC1);
  EXPECT_GE(e.keypoints.size(), 950u);
  EXPECT_LE(e.keypoints.size(), 1000u);
  int cells[4][4] = {};
  for (const cv::KeyPoint& kp : e.keypoints) {
    ASSERT_GE(kp.pt.x, 0);
    ASSERT_LT(kp.pt.x, 640);
    ASSERT_GE(kp.pt.y, 0);
    ASSERT_LT(kp.pt.y, 480);
    ASSERT_GE(kp.angle, 0);
    ASSERT_LT(kp.angle, 360);
    ASSERT_GE(kp.octave, 0);
    ASSERT_LT(kp.octave, 8);
    EXPECT_NEAR(kp.size, 31 * std::pow(1.2, kp.octave), 1e-3);
    EXPECT_GE(kp.response, 7);
    ++cells[static_cast<int>(kp.pt.y / 120)][static_cast<int>(kp.pt.x / 160)];
  }
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) EXPECT_GE(cells[r][c], 25) << "cell " << r << "," << c;
  }
}

TEST(OrbExtractorTest, LowContrastCellsFallBackToMinThreshold) {
  // Left half: full-contrast texture. Right half: the same texture squeezed to +-8 grey levels,
  // where FAST at 20 finds nothing but FAST at 7 does.
  cv::Mat image = MakeTexture(640, 480, 6);
  cv::Mat right = image(cv::Rect(320, 0, 320, 480));
  right.convertTo(right, CV_8UC1, 16.0 / 255.0, 120.0);
  const auto count_right = [](const std::vector<cv::KeyPoint>& kps) {
    return std::count_if(kps.begin(), kps.end(),
                         [](const cv::KeyPoint& kp) { return kp.pt.x > 340; });
  };
  const Extraction with_fallback = Extract(image);
  OrbOptions no_fallback;
  no_fallback.min_th_fast = no_fallback.ini_th_fast;
  const Extraction without = Extract(image, cv::Mat(), no_fallback);
  EXPECT_EQ(count_right(without.keypoints), 0);
  EXPECT_GT(count_right(with_fallback.keypoints), 50);  // measured 97
}

TEST(OrbExtractorTest, TinyImageGivesNoKeypoints) {
  std::vector<cv::KeyPoint> kps(3);
  cv::Mat desc;
  OrbExtractor(OrbOptions()).Extract(MakeTexture(30, 30, 1), cv::Mat(), &kps, &desc);
  EXPECT_TRUE(kps.empty());
  EXPECT_EQ(desc.rows, 0);
}

TEST(OrbExtractorTest, PerLevelCountsFollowGeometricSeries) {
  const OrbExtractor extractor{OrbOptions()};
  std::vector<cv::KeyPoint> kps;
  cv::Mat desc;
  extractor.Extract(MakeTexture(640, 480, 2), cv::Mat(), &kps, &desc);
  std::vector<int> counts(8, 0);
  for (const cv::KeyPoint& kp : kps) ++counts[kp.octave];
  for (int l = 0; l < 8; ++l) {
    const int target = extractor.features_per_level()[l];
    EXPECT_LE(counts[l], target) << "level " << l;
    EXPECT_GE(counts[l], 0.85 * target) << "level " << l;
  }
  EXPECT_GT(counts[0], counts[4]);
}

TEST(OrbExtractorTest, IgnoreMaskRegionsHaveNoKeypointsAndBudgetMovesElsewhere) {
  const cv::Mat image = MakeTexture(640, 480, 3);
  cv::Mat mask(480, 640, CV_8UC1, cv::Scalar(0));
  cv::rectangle(mask, cv::Rect(200, 100, 220, 300), cv::Scalar(255), cv::FILLED);  // a "person"
  cv::circle(mask, cv::Point(80, 80), 50, cv::Scalar(1), cv::FILLED);  // any non-zero value
  const Extraction unmasked = Extract(image);
  const Extraction masked = Extract(image, mask);
  int inside_before = 0;
  for (const cv::KeyPoint& kp : unmasked.keypoints) {
    inside_before += mask.at<uint8_t>(cvRound(kp.pt.y), cvRound(kp.pt.x)) != 0;
  }
  EXPECT_GT(inside_before, 150);  // the mask covers a real share of the budget
  for (const cv::KeyPoint& kp : masked.keypoints) {
    EXPECT_EQ(mask.at<uint8_t>(cvRound(kp.pt.y), cvRound(kp.pt.x)), 0)
        << kp.pt << " octave " << kp.octave;
  }
  EXPECT_GE(masked.keypoints.size(), 930u);
}

// Angle (degrees) of the direction `angle_deg` after the linear part of `affine`.
double MapAngle(const cv::Mat& affine, double angle_deg) {
  const double a = angle_deg * CV_PI / 180.0;
  const double dx = affine.at<double>(0, 0) * std::cos(a) + affine.at<double>(0, 1) * std::sin(a);
  const double dy = affine.at<double>(1, 0) * std::cos(a) + affine.at<double>(1, 1) * std::sin(a);
  return std::atan2(dy, dx) * 180.0 / CV_PI;
}

double AngleError(double a, double b) {
  double d = std::fmod(std::abs(a - b), 360.0);
  return std::min(d, 360.0 - d);
}

// Skipping the low-threshold retry in cells the mask covers is only a speed-up: on masks of
// several shapes (blobs, a frame border, a mask of everything but thin strips, single holes)
// the keypoints and descriptors are exactly those of the extraction that retries every cell.
TEST(OrbExtractorTest, SkippingMaskedCellsDoesNotChangeTheResult) {
  const cv::Mat image = MakeTexture(640, 480, 11);
  std::vector<cv::Mat> masks;
  cv::Mat blobs(480, 640, CV_8UC1, cv::Scalar(0));
  cv::ellipse(blobs, {200, 260}, {90, 200}, 0, 0, 360, cv::Scalar(255), cv::FILLED);
  cv::circle(blobs, {520, 120}, 70, cv::Scalar(7), cv::FILLED);
  masks.push_back(blobs);
  cv::Mat border(480, 640, CV_8UC1, cv::Scalar(255));
  border(cv::Rect(100, 80, 400, 300)).setTo(0);
  masks.push_back(border);
  cv::Mat strips(480, 640, CV_8UC1, cv::Scalar(255));
  for (int x = 13; x < 640; x += 97) strips.col(x).setTo(0);  // one clear column every 97 px
  masks.push_back(strips);
  cv::Mat holes(480, 640, CV_8UC1, cv::Scalar(255));
  for (int y = 5; y < 480; y += 41) {
    for (int x = 3; x < 640; x += 53) holes.at<uint8_t>(y, x) = 0;  // single clear pixels
  }
  masks.push_back(holes);
  OrbOptions retry_all;
  retry_all.skip_masked_cells = false;
  for (size_t m = 0; m < masks.size(); ++m) {
    const Extraction fast = Extract(image, masks[m]);
    const Extraction reference = Extract(image, masks[m], retry_all);
    ASSERT_EQ(fast.keypoints.size(), reference.keypoints.size()) << "mask " << m;
    for (size_t i = 0; i < fast.keypoints.size(); ++i) {
      EXPECT_EQ(fast.keypoints[i].pt, reference.keypoints[i].pt) << "mask " << m << " kp " << i;
      EXPECT_EQ(fast.keypoints[i].octave, reference.keypoints[i].octave);
      EXPECT_EQ(fast.keypoints[i].angle, reference.keypoints[i].angle);
    }
    EXPECT_EQ(cv::norm(fast.descriptors, reference.descriptors, cv::NORM_HAMMING), 0.0)
        << "mask " << m;
  }
  EXPECT_GT(Extract(image, masks[0]).keypoints.size(), 500u);  // the test extracts something
}

// Prepare once (no mask), then Extract from the prepared pyramid with different masks: each gives
// the one-step Extract's keypoints and descriptors, and the pyramid is not changed by its use.
TEST(OrbExtractorTest, PreparedPyramidGivesTheOneStepResultForAnyMask) {
  const cv::Mat image = MakeTexture(640, 480, 12);
  cv::Mat blob(480, 640, CV_8UC1, cv::Scalar(0));
  cv::ellipse(blob, {300, 240}, {120, 220}, 0, 0, 360, cv::Scalar(255), cv::FILLED);
  const OrbExtractor extractor{OrbOptions()};
  const OrbPyramid pyramid = extractor.Prepare(image);
  ASSERT_EQ(pyramid.levels.size(), 8u);
  for (const cv::Mat& mask : {cv::Mat(), blob, cv::Mat()}) {
    std::vector<cv::KeyPoint> one, two;
    cv::Mat one_desc, two_desc;
    extractor.Extract(image, mask, &one, &one_desc);
    extractor.Extract(pyramid, mask, &two, &two_desc);
    ASSERT_EQ(one.size(), two.size());
    ASSERT_GT(one.size(), 500u);
    for (size_t i = 0; i < one.size(); ++i) {
      EXPECT_EQ(one[i].pt, two[i].pt) << i;
      EXPECT_EQ(one[i].octave, two[i].octave) << i;
      EXPECT_EQ(one[i].angle, two[i].angle) << i;
      EXPECT_EQ(one[i].response, two[i].response) << i;
    }
    EXPECT_EQ(cv::norm(one_desc, two_desc, cv::NORM_HAMMING), 0.0);
  }
  std::vector<cv::KeyPoint> kps;
  cv::Mat desc;
  EXPECT_THROW(extractor.Extract(pyramid, cv::Mat(240, 320, CV_8UC1, cv::Scalar(0)), &kps, &desc),
               InputError);
  EXPECT_THROW(extractor.Prepare(cv::Mat(480, 640, CV_32F, cv::Scalar(0))), InputError);
}

TEST(OrbExtractorTest, RotatingImageRotatesKeypointAngles) {
  const cv::Mat image = MakeTexture(640, 480, 4);
  for (double theta : {25.0, -70.0, 150.0}) {
    const cv::Mat affine = cv::getRotationMatrix2D(cv::Point2f(320, 240), theta, 1.0);
    cv::Mat rotated;
    cv::warpAffine(image, rotated, affine, image.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT_101);
    const Extraction a = Extract(image), b = Extract(rotated);
    std::vector<double> errors;
    for (const cv::KeyPoint& ka : a.keypoints) {
      const cv::Point2d p(affine.at<double>(0, 0) * ka.pt.x + affine.at<double>(0, 1) * ka.pt.y +
                              affine.at<double>(0, 2),
                          affine.at<double>(1, 0) * ka.pt.x + affine.at<double>(1, 1) * ka.pt.y +
                              affine.at<double>(1, 2));
      if (std::hypot(p.x - 320, p.y - 240) > 200) continue;  // stay clear of the warped border
      for (const cv::KeyPoint& kb : b.keypoints) {
        if (kb.octave == ka.octave && std::hypot(kb.pt.x - p.x, kb.pt.y - p.y) < 1.5) {
          errors.push_back(AngleError(kb.angle, MapAngle(affine, ka.angle)));
          break;
        }
      }
    }
    ASSERT_GE(errors.size(), 100u) << "theta " << theta;
    std::sort(errors.begin(), errors.end());
    RecordProperty("median_angle_error_deg_theta_" + std::to_string(static_cast<int>(theta)),
                   std::to_string(errors[errors.size() / 2]));
    RecordProperty("p80_angle_error_deg_theta_" + std::to_string(static_cast<int>(theta)),
                   std::to_string(errors[errors.size() * 8 / 10]));
    EXPECT_LT(errors[errors.size() / 2], 3.0) << "median angle error, theta " << theta;
    EXPECT_LT(errors[errors.size() * 8 / 10], 8.0) << "80th percentile, theta " << theta;
  }
}

TEST(OrbExtractorTest, DeterministicAcrossRunsAndInstances) {
  const cv::Mat image = MakeTexture(640, 480, 5);
  const Extraction a = Extract(image), b = Extract(image);
  ASSERT_EQ(a.keypoints.size(), b.keypoints.size());
  for (size_t i = 0; i < a.keypoints.size(); ++i) {
    EXPECT_EQ(a.keypoints[i].pt, b.keypoints[i].pt);
    EXPECT_EQ(a.keypoints[i].angle, b.keypoints[i].angle);
    EXPECT_EQ(a.keypoints[i].octave, b.keypoints[i].octave);
    EXPECT_EQ(a.keypoints[i].response, b.keypoints[i].response);
  }
  EXPECT_EQ(cv::norm(a.descriptors, b.descriptors, cv::NORM_HAMMING), 0.0);
}

TEST(DescriptorDistanceTest, HandMadeValues) {
  uint8_t a[32] = {}, b[32] = {};
  EXPECT_EQ(DescriptorDistance(a, b), 0);
  b[0] = 0x01;
  EXPECT_EQ(DescriptorDistance(a, b), 1);
  b[31] = 0xF0;  // 4 more bits, in the last word
  EXPECT_EQ(DescriptorDistance(a, b), 5);
  b[9] = 0xFF;
  b[17] = 0x81;
  EXPECT_EQ(DescriptorDistance(a, b), 15);
  EXPECT_EQ(DescriptorDistance(b, a), 15);
  std::fill(a, a + 32, 0xFF);
  std::fill(b, b + 32, 0x00);
  EXPECT_EQ(DescriptorDistance(a, b), 256);
  std::fill(b, b + 32, 0x55);  // every other bit
  EXPECT_EQ(DescriptorDistance(a, b), 128);
}

}  // namespace
}  // namespace detslam
