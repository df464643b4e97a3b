// Descriptor stability: warp an image by a known similarity (rotation + scale about the centre),
// extract ORB in both, match by brute force and check the matches against the true warp.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "detslam/features/matcher.h"
#include "detslam/features/orb_extractor.h"
#include "detslam/features/texture_for_test.h"
#include "support/shared_data.h"

namespace detslam {
namespace {

struct WarpMatchStats {
  size_t keypoints_a = 0, keypoints_b = 0;
  size_t matches = 0;
  size_t correct = 0;  // within 3 px of the warped position
  double CorrectFraction() const { return matches == 0 ? 0.0 : double(correct) / matches; }
};

std::ostream& operator<<(std::ostream& os, const WarpMatchStats& s) {
  return os << "keypoints " << s.keypoints_a << "/" << s.keypoints_b << ", matches " << s.matches
            << ", correct " << s.correct << " (" << 100.0 * s.CorrectFraction() << "%)";
}

// Warps `image` by rotation `angle_deg` (OpenCV convention) and `scale` about its centre.
WarpMatchStats WarpAndMatch(const cv::Mat& image, double angle_deg, double scale) {
  const cv::Point2f center(image.cols / 2.0f, image.rows / 2.0f);
  const cv::Mat affine = cv::getRotationMatrix2D(center, angle_deg, scale);
  cv::Mat warped;
  cv::warpAffine(image, warped, affine, image.size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT,
                 cv::Scalar(0));
  const OrbExtractor extractor{OrbOptions()};
  std::vector<cv::KeyPoint> kp_a, kp_b;
  cv::Mat desc_a, desc_b;
  extractor.Extract(image, cv::Mat(), &kp_a, &desc_a);
  extractor.Extract(warped, cv::Mat(), &kp_b, &desc_b);
  const std::vector<cv::DMatch> matches = MatchBruteForce(kp_a, desc_a, kp_b, desc_b, {});
  WarpMatchStats stats;
  stats.keypoints_a = kp_a.size();
  stats.keypoints_b = kp_b.size();
  stats.matches = matches.size();
  for (const cv::DMatch& m : matches) {
    const cv::Point2f& p = kp_a[m.queryIdx].pt;
    const double x =
        affine.at<double>(0, 0) * p.x + affine.at<double>(0, 1) * p.y + affine.at<double>(0, 2);
    const double y =
        affine.at<double>(1, 0) * p.x + affine.at<double>(1, 1) * p.y + affine.at<double>(1, 2);
    const cv::Point2f& q = kp_b[m.trainIdx].pt;
    if (std::hypot(q.x - x, q.y - y) <= 3.0) ++stats.correct;
  }
  ::testing::Test::RecordProperty("matches", static_cast<int>(stats.matches));
  ::testing::Test::RecordProperty("correct", static_cast<int>(stats.correct));
  return stats;
}

// Measured (default MatchOptions: ratio 0.7, distance <= 50, orientation check): rotation 30 deg
// 282 matches / 98.6% correct; scale 1.3: 203 / 96.6%; both: 115-149 correct, 87-94% over seven
// texture seeds; the TUM frame: 272 / 97.8%, 191 / 95.3%, 137 / 93.4%. The thresholds below leave
// room for platform differences in resize/warp rounding.
constexpr double kMinCorrectFraction = 0.8;
constexpr size_t kMinCorrect = 100;

TEST(OrbMatchingTest, StableUnderRotationOnTexture) {
  const WarpMatchStats s = WarpAndMatch(detslam::testing::MakeTexture(640, 480, 11), 30.0, 1.0);
  EXPECT_GE(s.correct, kMinCorrect) << s;
  EXPECT_GE(s.CorrectFraction(), kMinCorrectFraction) << s;
}

TEST(OrbMatchingTest, StableUnderScaleOnTexture) {
  const WarpMatchStats s = WarpAndMatch(detslam::testing::MakeTexture(640, 480, 12), 0.0, 1.3);
  EXPECT_GE(s.correct, kMinCorrect) << s;
  EXPECT_GE(s.CorrectFraction(), kMinCorrectFraction) << s;
}

TEST(OrbMatchingTest, StableUnderRotationAndScaleOnTexture) {
  const WarpMatchStats s = WarpAndMatch(detslam::testing::MakeTexture(640, 480, 13), 30.0, 1.3);
  EXPECT_GE(s.correct, kMinCorrect) << s;
  EXPECT_GE(s.CorrectFraction(), kMinCorrectFraction) << s;
}

TEST(DataOrbMatchingTest, StableUnderRotationAndScaleOnTumFrame) {
  const std::string relative =
      "data/tum/rgbd_dataset_freiburg2_desk_subset50/rgb/1311868164.363181.png";
  DETSLAM_REQUIRE_SHARED(relative);
  const cv::Mat gray = cv::imread(detslam::testing::SharedPath(relative), cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(gray.empty());
  for (auto [angle, scale] : {std::pair{30.0, 1.0}, {0.0, 1.3}, {30.0, 1.3}}) {
    const WarpMatchStats s = WarpAndMatch(gray, angle, scale);
    EXPECT_GE(s.correct, kMinCorrect) << "angle " << angle << " scale " << scale << ": " << s;
    EXPECT_GE(s.CorrectFraction(), kMinCorrectFraction)
        << "angle " << angle << " scale " << scale << ": " << s;
  }
}

}  // namespace
}  // namespace detslam
