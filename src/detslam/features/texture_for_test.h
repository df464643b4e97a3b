// Test helper (header-only, used by the features tests): a deterministic textured image made of
// random filled rectangles and ellipses, lightly blurred. Rich in corners at every scale.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "detslam/core/rng.h"

namespace detslam::testing {

inline cv::Mat MakeTexture(int width, int height, uint64_t seed, int num_shapes = 900) {
  Rng rng(seed);
  cv::Mat image(height, width, CV_8UC1, cv::Scalar(128));
  for (int i = 0; i < num_shapes; ++i) {
    const int size = rng.UniformInt(4, 40);
    // One draw per declarator (argument order is unspecified: gcc and clang differ), in the
    // order gcc drew them when they were arguments, so the images stay as they were.
    const int cy = rng.UniformInt(-10, height + 10), cx = rng.UniformInt(-10, width + 10);
    const cv::Point center(cx, cy);
    const cv::Scalar color(rng.UniformInt(0, 255));
    if (rng.UniformInt(0, 1) == 0) {
      const int dy = rng.UniformInt(-size, size), dx = rng.UniformInt(-size, size);
      cv::rectangle(image, center, cv::Point(center.x + dx, center.y + dy), color, cv::FILLED);
    } else {
      const double angle = rng.Uniform(0, 180);
      const int minor = rng.UniformInt(2, size);
      cv::ellipse(image, center, cv::Size(size, minor), angle, 0, 360, color, cv::FILLED,
                  cv::LINE_AA);
    }
  }
  cv::GaussianBlur(image, image, cv::Size(3, 3), 0.8);
  return image;
}

}  // namespace detslam::testing
