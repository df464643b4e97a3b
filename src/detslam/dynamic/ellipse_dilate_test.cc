#include "detslam/dynamic/ellipse_dilate.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace detslam {
namespace {

cv::Mat Reference(const cv::Mat& src, int radius) {
  cv::Mat dst;
  cv::dilate(src, dst,
             cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * radius + 1, 2 * radius + 1)));
  return dst;
}

// Pixel for pixel equal to cv::dilate with the elliptic kernel: binary masks (blobs and isolated
// pixels, touching the borders), grey images, images smaller than the kernel, every radius used.
TEST(DilateEllipse, EqualsOpenCvDilateWithTheEllipticKernel) {
  cv::RNG rng(7);
  const std::vector<cv::Size> sizes = {{1, 1}, {5, 3}, {17, 40}, {160, 120}, {97, 211}};
  for (const cv::Size& size : sizes) {
    for (int radius : {0, 1, 2, 3, 4, 5, 7, 10, 12, 15, 16, 24, 31}) {
      cv::Mat binary = cv::Mat::zeros(size, CV_8UC1);
      for (int k = 0; k < 4; ++k) {
        cv::circle(binary, {rng.uniform(-5, size.width + 5), rng.uniform(-5, size.height + 5)},
                   rng.uniform(1, 20), cv::Scalar(255), cv::FILLED);
        binary.at<uint8_t>(rng.uniform(0, size.height), rng.uniform(0, size.width)) = 255;
      }
      cv::Mat grey(size, CV_8UC1);
      rng.fill(grey, cv::RNG::UNIFORM, 0, 256);
      for (const cv::Mat& src : {binary, grey}) {
        const cv::Mat before = src.clone();
        const cv::Mat fast = DilateEllipse(src, radius);
        ASSERT_EQ(cv::norm(src, before, cv::NORM_INF), 0.0) << "the input was changed";
        const cv::Mat reference = Reference(src, radius);
        ASSERT_EQ(fast.size(), reference.size());
        ASSERT_EQ(fast.type(), CV_8UC1);
        EXPECT_EQ(cv::norm(fast, reference, cv::NORM_INF), 0.0)
            << "size " << size << ", radius " << radius;
      }
    }
  }
}

// Only the window around the non-zero pixels is dilated: a person-sized blob far from the borders,
// one touching a corner, single pixels, an empty mask.
TEST(DilateEllipse, EqualsOpenCvDilateWhereOnlyPartOfTheImageIsSet) {
  const cv::Size size(640, 480);
  cv::Mat centre = cv::Mat::zeros(size, CV_8UC1);
  cv::ellipse(centre, {320, 260}, {60, 150}, 0, 0, 360, cv::Scalar(255), cv::FILLED);
  cv::Mat corner = cv::Mat::zeros(size, CV_8UC1);
  cv::rectangle(corner, {600, 0}, {639, 30}, cv::Scalar(255), cv::FILLED);
  cv::Mat pixels = cv::Mat::zeros(size, CV_8UC1);
  pixels.at<uint8_t>(3, 200) = 7;
  pixels.at<uint8_t>(300, 5) = 255;
  const cv::Mat empty = cv::Mat::zeros(size, CV_8UC1);
  for (const cv::Mat& src : {centre, corner, pixels, empty}) {
    for (int radius : {3, 10, 15, 24, 40}) {
      const cv::Mat fast = DilateEllipse(src, radius);
      ASSERT_EQ(fast.size(), size);
      EXPECT_EQ(cv::norm(fast, Reference(src, radius), cv::NORM_INF), 0.0) << "radius " << radius;
    }
  }
}

TEST(DilateEllipse, RejectsOtherTypesAndNegativeRadii) {
  EXPECT_DEATH(DilateEllipse(cv::Mat::zeros(4, 4, CV_32FC1), 2), "");
  EXPECT_DEATH(DilateEllipse(cv::Mat::zeros(4, 4, CV_8UC1), -1), "");
}

}  // namespace
}  // namespace detslam
