#include "detslam/segmentation/person_mask.h"

#include <filesystem>
#include <opencv2/imgproc.hpp>

#include "detslam/core/check.h"

namespace detslam {

namespace {
constexpr int kSide = 256;
}  // namespace

PersonMaskModel::PersonMaskModel(const std::string& onnx_path) : path_(onnx_path) {
  if (!std::filesystem::is_regular_file(onnx_path)) {
    throw InputError(onnx_path, 0, "person mask model (selfie_segmentation.onnx) not found");
  }
  try {
    net_ = cv::dnn::readNetFromONNX(onnx_path);
  } catch (const cv::Exception& e) {
    throw InputError(onnx_path, 0, std::string("cannot load ONNX model: ") + e.what());
  }
  if (net_.empty()) throw InputError(onnx_path, 0, "cannot load ONNX model");
  net_.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  net_.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
}

cv::Mat PersonMaskModel::Probability(const cv::Mat& bgr, const cv::Rect& roi) {
  DETSLAM_CHECK(bgr.type() == CV_8UC3);
  const cv::Rect r = roi & cv::Rect(0, 0, bgr.cols, bgr.rows);
  DETSLAM_CHECK_MSG(!r.empty(), "empty crop for the person mask");
  cv::Mat resized, rgb, input;
  cv::resize(bgr(r), resized, cv::Size(kSide, kSide), 0, 0, cv::INTER_LINEAR);
  cv::cvtColor(resized, rgb, cv::COLOR_BGR2RGB);
  rgb.convertTo(input, CV_32FC3, 1.0 / 255.0);
  // NHWC blob sharing the continuous HxWx3 float data.
  const int dims[4] = {1, kSide, kSide, 3};
  cv::Mat blob(4, dims, CV_32F, input.data);
  net_.setInput(blob);
  cv::Mat out = net_.forward();
  if (out.total() != static_cast<size_t>(kSide * kSide)) {
    throw InputError(
        path_, 0,
        "unexpected output size " + std::to_string(out.total()) + " (expected 256x256x1)");
  }
  cv::Mat prob(kSide, kSide, CV_32F, out.ptr<float>());
  cv::Mat back;
  cv::resize(prob, back, r.size(), 0, 0, cv::INTER_LINEAR);
  return back;
}

cv::Mat PersonMaskModel::Mask(const cv::Mat& bgr, const cv::Rect& roi, float threshold) {
  cv::Mat mask(bgr.size(), CV_8UC1, cv::Scalar(0));
  const cv::Rect r = roi & cv::Rect(0, 0, bgr.cols, bgr.rows);
  if (r.empty()) return mask;
  const cv::Mat prob = Probability(bgr, r);
  cv::Mat crop_mask = prob > threshold;
  crop_mask.copyTo(mask(r));
  return mask;
}

}  // namespace detslam
