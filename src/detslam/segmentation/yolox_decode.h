// YOLOX pre- and post-processing as pure functions (no network): letterbox the image into the
// square network input, decode the anchor-free output over the stride-8/16/32 grids, and apply
// per-class non-maximum suppression. See ../shared/models/README.md for the tensor layouts.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace detslam {

// One decoded detection in original-image pixels (not yet clipped).
struct RawDetection {
  int class_id = 0;  // index into the model's class list
  float score = 0;   // objectness * class score
  cv::Rect2d box;    // x, y, width, height in original-image pixels
};

// Letterbox as YOLOX's demo does it: the image scaled by r = min(S / w, S / h) (bilinear), placed
// at the top-left of an S x S canvas filled with 114. Returns the canvas (same type as `bgr`) and
// sets *scale = r, so that original = network / r.
cv::Mat LetterboxTopLeft(const cv::Mat& bgr, int input_size, double* scale);

// Number of output rows of a YOLOX network with square input `input_size` (strides 8, 16, 32):
// (S/8)^2 + (S/16)^2 + (S/32)^2, e.g. 3549 for 416. Returns 0 if S is not a multiple of 32.
int YoloxOutputRows(int input_size);

// Decodes a YOLOX output of `rows` x `cols` floats (row-major; cols = 5 + classes: dx, dy, log w,
// log h, objectness, class scores, sigmoids already applied) for a square input of `input_size`.
// Cells are ordered stride 8 first, then 16, then 32, each row-major over its grid (y outer).
// Per cell: cx = (dx + gx) * stride, cy = (dy + gy) * stride, w = exp(log w) * stride, likewise h;
// class = argmax of the class scores, score = obj * class score; kept if score >= threshold.
// Boxes are divided by `scale` (the letterbox ratio). Requires rows == YoloxOutputRows(input_size).
std::vector<RawDetection> DecodeYolox(const float* data, int rows, int cols, int input_size,
                                      double scale, float score_threshold);

// Per-class NMS (cv::dnn::NMSBoxes on each class separately); result sorted by descending score,
// ties by class id and position so the order is deterministic.
std::vector<RawDetection> NmsPerClass(const std::vector<RawDetection>& detections,
                                      float score_threshold, float nms_threshold);

}  // namespace detslam
