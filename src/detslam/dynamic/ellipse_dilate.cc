#include "detslam/dynamic/ellipse_dilate.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "detslam/core/check.h"

namespace detslam {

cv::Mat DilateEllipse(const cv::Mat& src, int radius) {
  DETSLAM_CHECK(src.type() == CV_8UC1);
  DETSLAM_CHECK(radius >= 0);
  if (radius == 0 || src.empty()) return src.clone();
  // Only the non-zero pixels' bounding box grown by the radius can change: dilate that window
  // alone (a person is a fraction of the image). Pixels beyond the window are zero in `src` and
  // stay zero, and those beyond the image count for nothing in both.
  const cv::Rect image(0, 0, src.cols, src.rows);
  const cv::Rect nonzero = cv::boundingRect(src);
  if (nonzero.empty()) return cv::Mat::zeros(src.size(), CV_8UC1);
  const cv::Rect window =
      cv::Rect(nonzero.x - radius, nonzero.y - radius, nonzero.width + 2 * radius,
               nonzero.height + 2 * radius) &
      image;
  if (window != image) {
    cv::Mat out = cv::Mat::zeros(src.size(), CV_8UC1);
    DilateEllipse(src(window), radius).copyTo(out(window));
    return out;
  }
  const int size = 2 * radius + 1;
  const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(size, size));
  const auto opencv_dilate = [&] {
    cv::Mat dst;
    cv::dilate(src, dst, kernel);
    return dst;
  };
  // Below this radius OpenCV's own dilation is as fast (build/bench/detslam_bench_dynamic).
  constexpr int kRowsFromRadius = 8;
  if (radius < kRowsFromRadius) return opencv_dilate();
  // Half-width of each kernel row's run of ones (-1: an empty row).
  std::vector<int> half(static_cast<size_t>(size), -1);
  int widest = -1;
  for (int j = 0; j < size; ++j) {
    const uint8_t* row = kernel.ptr<uint8_t>(j);
    const int first = static_cast<int>(std::find(row, row + size, 1) - row);
    const int count = cv::countNonZero(kernel.row(j));
    if (count == 0) continue;
    // A run centred on the anchor: otherwise this decomposition does not hold.
    if (count % 2 != 1 || first != radius - count / 2 ||
        cv::countNonZero(kernel.row(j).colRange(first, first + count)) != count) {
      return opencv_dilate();
    }
    half[static_cast<size_t>(j)] = count / 2;
    widest = std::max(widest, count / 2);
  }
  const cv::Mat step = cv::Mat::ones(1, 3, CV_8UC1);
  cv::Mat out = cv::Mat::zeros(src.size(), CV_8UC1);
  cv::Mat horizontal = src;  // src dilated horizontally by w pixels each side
  for (int w = 0; w <= widest; ++w) {
    if (w > 0) {
      cv::Mat wider;  // not in place: at w = 1 `horizontal` is the caller's image
      cv::dilate(horizontal, wider, step);
      horizontal = wider;
    }
    for (int j = 0; j < size; ++j) {
      if (half[static_cast<size_t>(j)] != w) continue;
      // dst(x, y) = max over the kernel of src(x + i - radius, y + j - radius): row y takes the
      // horizontal dilation's row y + dy.
      const int dy = j - radius;
      const int y0 = std::max(0, -dy), y1 = std::min(src.rows, src.rows - dy);
      if (y1 <= y0) continue;
      cv::Mat target = out.rowRange(y0, y1);
      cv::max(target, horizontal.rowRange(y0 + dy, y1 + dy), target);
    }
  }
  return out;
}

}  // namespace detslam
