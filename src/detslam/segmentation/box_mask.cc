#include "detslam/segmentation/box_mask.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "detslam/core/check.h"

namespace detslam {

bool DominantDepthOptions::Check(std::string* error) const {
  std::string e;
  if (!(bin_m > 0))
    e = "dominant-depth bin width must be > 0";
  else if (!(tolerance_m >= 0))
    e = "dominant-depth tolerance must be >= 0";
  else if (min_valid_pixels < 1)
    e = "dominant-depth min_valid_pixels must be >= 1";
  else if (!(min_depth_m >= 0 && max_depth_m > min_depth_m))
    e = "depth range must be 0 <= min < max";
  if (!e.empty() && error != nullptr) *error = e;
  return e.empty();
}

cv::Rect ExpandBox(const cv::Rect& box, double fraction, const cv::Size& size) {
  const int dx = static_cast<int>(std::lround(box.width * fraction));
  const int dy = static_cast<int>(std::lround(box.height * fraction));
  const cv::Rect grown(box.x - dx, box.y - dy, box.width + 2 * dx, box.height + 2 * dy);
  return grown & cv::Rect(0, 0, size.width, size.height);
}

cv::Mat DominantDepthBoxMask(const cv::Mat& depth_m, const cv::Rect& box, const cv::Size& size,
                             const DominantDepthOptions& options) {
  cv::Mat mask(size, CV_8UC1, cv::Scalar(0));
  const cv::Rect roi = box & cv::Rect(0, 0, size.width, size.height);
  if (roi.empty()) return mask;
  if (depth_m.empty()) {
    mask(roi).setTo(255);
    return mask;
  }
  DETSLAM_CHECK(depth_m.type() == CV_32FC1 && depth_m.size() == size);
  auto valid = [&](float d) { return d >= options.min_depth_m && d <= options.max_depth_m; };
  float lo = 0;
  int n_valid = 0;
  for (int y = roi.y; y < roi.br().y; ++y) {
    const float* row = depth_m.ptr<float>(y);
    for (int x = roi.x; x < roi.br().x; ++x) {
      if (!valid(row[x])) continue;
      lo = n_valid == 0 ? row[x] : std::min(lo, row[x]);
      ++n_valid;
    }
  }
  if (n_valid < options.min_valid_pixels) {
    mask(roi).setTo(255);
    return mask;
  }
  const int bins = static_cast<int>((options.max_depth_m - lo) / options.bin_m) + 1;
  std::vector<int> count(bins, 0);
  std::vector<double> sum(bins, 0.0);
  for (int y = roi.y; y < roi.br().y; ++y) {
    const float* row = depth_m.ptr<float>(y);
    for (int x = roi.x; x < roi.br().x; ++x) {
      if (!valid(row[x])) continue;
      const int b = std::min(bins - 1, static_cast<int>((row[x] - lo) / options.bin_m));
      ++count[b];
      sum[b] += row[x];
    }
  }
  int best = 0, best_smoothed = -1;
  for (int b = 0; b < bins; ++b) {
    const int s = count[b] + (b > 0 ? count[b - 1] : 0) + (b + 1 < bins ? count[b + 1] : 0);
    if (s > best_smoothed || (s == best_smoothed && count[b] > count[best])) {
      best_smoothed = s;
      best = b;
    }
  }
  // The dominant bin itself may be empty (between two full neighbours): widen to the neighbours.
  double total = 0;
  int n = 0;
  for (int b = std::max(0, best - 1); b <= std::min(bins - 1, best + 1); ++b) {
    if (count[b] > 0 && (b == best || count[best] == 0)) {
      total += sum[b];
      n += count[b];
    }
  }
  const double mode = total / std::max(1, n);
  for (int y = roi.y; y < roi.br().y; ++y) {
    const float* row = depth_m.ptr<float>(y);
    uint8_t* out = mask.ptr<uint8_t>(y);
    for (int x = roi.x; x < roi.br().x; ++x) {
      if (valid(row[x]) && std::abs(row[x] - mode) <= options.tolerance_m) out[x] = 255;
    }
  }
  return mask;
}

double MaskIou(const cv::Mat& a, const cv::Mat& b) {
  DETSLAM_CHECK(a.size() == b.size() && a.type() == CV_8UC1 && b.type() == CV_8UC1);
  cv::Mat ba = a != 0, bb = b != 0;
  const double inter = cv::countNonZero(ba & bb);
  const double uni = cv::countNonZero(ba | bb);
  return uni > 0 ? inter / uni : 0.0;
}

double BoxIou(const cv::Rect& a, const cv::Rect& b) {
  const double inter = (a & b).area();
  const double uni = static_cast<double>(a.area()) + b.area() - inter;
  return uni > 0 ? inter / uni : 0.0;
}

cv::Mat PersonMaskOrDepth(const cv::Mat& model_mask, const cv::Rect& box, double min_fill,
                          const cv::Mat& depth_m, const DominantDepthOptions& options) {
  const cv::Rect b = box & cv::Rect(0, 0, model_mask.cols, model_mask.rows);
  const double fill =
      b.empty() ? 0.0 : static_cast<double>(cv::countNonZero(model_mask(b))) / b.area();
  if (!b.empty() && fill >= min_fill) return model_mask;
  return DominantDepthBoxMask(depth_m, box, model_mask.size(), options);
}

}  // namespace detslam
