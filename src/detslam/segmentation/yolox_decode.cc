#include "detslam/segmentation/yolox_decode.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <opencv2/dnn.hpp>
#include <opencv2/imgproc.hpp>

#include "detslam/core/check.h"

namespace detslam {

cv::Mat LetterboxTopLeft(const cv::Mat& bgr, int input_size, double* scale) {
  DETSLAM_CHECK(!bgr.empty() && input_size > 0);
  const double r = std::min(static_cast<double>(input_size) / bgr.cols,
                            static_cast<double>(input_size) / bgr.rows);
  const int w = std::max(1, static_cast<int>(std::lround(bgr.cols * r)));
  const int h = std::max(1, static_cast<int>(std::lround(bgr.rows * r)));
  cv::Mat canvas(input_size, input_size, bgr.type(), cv::Scalar::all(114));
  cv::Mat resized;
  cv::resize(bgr, resized, cv::Size(std::min(w, input_size), std::min(h, input_size)), 0, 0,
             cv::INTER_LINEAR);
  resized.copyTo(canvas(cv::Rect(0, 0, resized.cols, resized.rows)));
  if (scale != nullptr) *scale = r;
  return canvas;
}

int YoloxOutputRows(int input_size) {
  if (input_size <= 0 || input_size % 32 != 0) return 0;
  int rows = 0;
  for (int stride : {8, 16, 32}) rows += (input_size / stride) * (input_size / stride);
  return rows;
}

std::vector<RawDetection> DecodeYolox(const float* data, int rows, int cols, int input_size,
                                      double scale, float score_threshold) {
  DETSLAM_CHECK_MSG(rows == YoloxOutputRows(input_size),
                    "YOLOX output has " << rows << " rows, input size " << input_size);
  DETSLAM_CHECK(cols > 5 && scale > 0);
  std::vector<RawDetection> out;
  int row = 0;
  for (int stride : {8, 16, 32}) {
    const int n = input_size / stride;
    for (int gy = 0; gy < n; ++gy) {
      for (int gx = 0; gx < n; ++gx, ++row) {
        const float* p = data + static_cast<size_t>(row) * cols;
        const float obj = p[4];
        if (obj < score_threshold) continue;  // score = obj * cls <= obj
        int best = 0;
        for (int c = 1; c < cols - 5; ++c) {
          if (p[5 + c] > p[5 + best]) best = c;
        }
        const float score = obj * p[5 + best];
        if (score < score_threshold) continue;
        const double cx = (p[0] + gx) * stride, cy = (p[1] + gy) * stride;
        const double w = std::exp(static_cast<double>(p[2])) * stride;
        const double h = std::exp(static_cast<double>(p[3])) * stride;
        RawDetection d;
        d.class_id = best;
        d.score = score;
        d.box = cv::Rect2d((cx - 0.5 * w) / scale, (cy - 0.5 * h) / scale, w / scale, h / scale);
        out.push_back(d);
      }
    }
  }
  return out;
}

std::vector<RawDetection> NmsPerClass(const std::vector<RawDetection>& detections,
                                      float score_threshold, float nms_threshold) {
  std::map<int, std::vector<size_t>> by_class;
  for (size_t i = 0; i < detections.size(); ++i) by_class[detections[i].class_id].push_back(i);
  std::vector<RawDetection> kept;
  for (const auto& [cls, members] : by_class) {
    std::vector<cv::Rect2d> boxes;
    std::vector<float> scores;
    for (size_t i : members) {
      boxes.push_back(detections[i].box);
      scores.push_back(detections[i].score);
    }
    std::vector<int> keep;
    cv::dnn::NMSBoxes(boxes, scores, score_threshold, nms_threshold, keep);
    for (int k : keep) kept.push_back(detections[members[k]]);
  }
  std::sort(kept.begin(), kept.end(), [](const RawDetection& a, const RawDetection& b) {
    if (a.score != b.score) return a.score > b.score;
    if (a.class_id != b.class_id) return a.class_id < b.class_id;
    if (a.box.x != b.box.x) return a.box.x < b.box.x;
    return a.box.y < b.box.y;
  });
  return kept;
}

}  // namespace detslam
