// Per-box person masks with MediaPipe Selfie Segmentation (ONNX, 1x256x256x3 NHWC RGB in 0..1,
// output 1x256x256x1 person probability), run on the crop of each (expanded) person box.
#pragma once

#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>
#include <string>

namespace detslam {

class PersonMaskModel {
 public:
  // Loads the ONNX file. Throws InputError naming the file if it is missing or unreadable.
  explicit PersonMaskModel(const std::string& onnx_path);

  // Person probability of the crop `roi` of `bgr` (CV_32FC1, roi size): the crop resized to
  // 256x256, converted to RGB 0..1, run through the network, the output resized back (bilinear).
  cv::Mat Probability(const cv::Mat& bgr, const cv::Rect& roi);

  // Full-image CV_8UC1 mask (255 = person): Probability(roi) > threshold placed into `roi`.
  cv::Mat Mask(const cv::Mat& bgr, const cv::Rect& roi, float threshold = 0.5f);

 private:
  std::string path_;
  cv::dnn::Net net_;
};

}  // namespace detslam
