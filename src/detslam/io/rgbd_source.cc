#include "detslam/io/rgbd_source.h"

#include <opencv2/imgproc.hpp>

namespace detslam {

std::string ImageSizeText(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

cv::Mat DecodedToBgr(const cv::Mat& decoded) {
  cv::Mat bgr;
  switch (decoded.channels()) {
    case 1:
      cv::cvtColor(decoded, bgr, cv::COLOR_GRAY2BGR);
      return bgr;
    case 3:
      return decoded;
    case 4:
      cv::cvtColor(decoded, bgr, cv::COLOR_BGRA2BGR);
      return bgr;
    default:
      return cv::Mat();
  }
}

}  // namespace detslam
