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
    const cv::Point center(rng.UniformInt(-10, width + 10), rng.UniformInt(-10, height + 10));
    const cv::Scalar color(rng.UniformInt(0, 255));
    if (rng.UniformInt(0, 1) == 0) {
      const cv::Point corner(center.x + rng.UniformInt(-size, size),
                             center.y + rng.UniformInt(-size, size));
      cv::rectangle(image, center, corner, color, cv::FILLED);
    } else {
      cv::ellipse(image, center, cv::Size(size, rng.UniformInt(2, size)), rng.Uniform(0, 180), 0,
                  360, color, cv::FILLED, cv::LINE_AA);
    }
  }
  cv::GaussianBlur(image, image, cv::Size(3, 3), 0.8);
  return image;
}

}  // namespace detslam::testing
