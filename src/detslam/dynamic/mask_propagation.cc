#include "detslam/dynamic/mask_propagation.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <sstream>

#include "detslam/core/check.h"
#include "detslam/dynamic/ellipse_dilate.h"

namespace detslam {
namespace {

double MedianOf(std::vector<float> v) {
  const size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  return v[mid];
}

cv::Mat Grow(const cv::Mat& mask, int px) {
  if (mask.empty() || px <= 0) return mask;
  return DilateEllipse(mask, px);
}

}  // namespace

bool MaskPropagationOptions::Check(std::string* error) const {
  std::ostringstream os;
  if (max_corners < 1) os << "max_corners must be >= 1; ";
  if (grow_px_per_frame < 0) os << "grow_px_per_frame must be >= 0; ";
  if (min_tracked < 1) os << "min_tracked must be >= 1; ";
  if (flow_scale != 1 && flow_scale != 2 && flow_scale != 4) os << "flow_scale must be 1, 2 or 4; ";
  if (error) *error = os.str();
  return os.str().empty();
}

MaskPropagator::MaskPropagator(MaskPropagationOptions options) : options_(options) {
  std::string error;
  DETSLAM_CHECK_MSG(options_.Check(&error), "invalid MaskPropagationOptions: " << error);
}

int NearestShift(double d) {
  // warpAffine's nearest neighbour: source x = (round(-d * 2^10) + x * 2^10 + 2^9) >> 10.
  constexpr int kBits = 10;
  return -((cvRound(-d * (1 << kBits)) + (1 << (kBits - 1))) >> kBits);
}

cv::Mat ShiftMask(const cv::Mat& mask, double dx, double dy) {
  if (mask.empty()) return mask;
  // A whole-pixel copy: the shift cv::warpAffine(INTER_NEAREST) makes of a translation, without
  // its per-pixel coordinate arithmetic over the whole image.
  const int sx = NearestShift(dx), sy = NearestShift(dy);
  cv::Mat out = cv::Mat::zeros(mask.size(), mask.type());
  const cv::Rect image(0, 0, mask.cols, mask.rows);
  const cv::Rect to = cv::Rect(sx, sy, mask.cols, mask.rows) & image;
  if (!to.empty()) mask(to - cv::Point(sx, sy)).copyTo(out(to));
  return out;
}

cv::Mat MaskPropagator::Reduced(const cv::Mat& gray) const {
  if (options_.flow_scale == 1) return gray.clone();
  cv::Mat out = gray;
  for (int s = options_.flow_scale; s > 1; s /= 2) {
    cv::Mat half;
    cv::pyrDown(out, half);
    out = half;
  }
  return out;
}

void MaskPropagator::Reset(const cv::Mat& gray, std::vector<Instance> instances) {
  DETSLAM_CHECK(gray.type() == CV_8UC1);
  last_gray_ = Reduced(gray);
  full_size_ = gray.size();
  last_pyramid_.clear();
  instances_ = std::move(instances);
  age_ = 0;
}

std::vector<Instance> MaskPropagator::Propagate(const cv::Mat& gray, int frames) {
  DETSLAM_CHECK(gray.type() == CV_8UC1);
  DETSLAM_CHECK(frames >= 1);
  if (last_gray_.empty()) return {};
  DETSLAM_CHECK_MSG(gray.size() == full_size_, "image size changed during the sequence");
  age_ += frames;
  const cv::Rect image(0, 0, gray.cols, gray.rows);
  // A 21-pixel window at full resolution, over 3 pyramid levels above the images: the reduced
  // images' window is as wide in the full image (odd), and their pyramid as deep, so that the
  // search reaches at least as far in full-resolution pixels (the window's half-width times 2^3
  // at the coarsest level).
  const int scale = options_.flow_scale;
  const int side = std::max(5, (21 / scale) | 1);
  const cv::Size window(side, side);
  constexpr int kLevels = 3;
  const cv::Mat small = Reduced(gray);
  const cv::Rect small_image(0, 0, small.cols, small.rows);
  // Both images' pyramids are built once per call (not once per instance); this frame's is the
  // next call's previous one.
  std::vector<cv::Mat> pyramid;
  if (!instances_.empty()) {
    if (last_pyramid_.empty()) {
      cv::buildOpticalFlowPyramid(last_gray_, last_pyramid_, window, kLevels);
    }
    cv::buildOpticalFlowPyramid(small, pyramid, window, kLevels);
  }
  for (Instance& inst : instances_) {
    // Corners inside the instance, searched in its box only (not over the whole image), in the
    // reduced images: the box rounded outwards, the mask reduced by nearest neighbour.
    const cv::Rect box = inst.box & image;
    const cv::Rect roi =
        cv::Rect(cv::Point(box.x / scale, box.y / scale),
                 cv::Point((box.x + box.width + scale - 1) / scale,
                           (box.y + box.height + scale - 1) / scale)) &
        small_image;
    cv::Mat region;
    if (!inst.mask.empty() && !roi.empty()) {
      if (scale == 1) {
        region = inst.mask(roi);
      } else {
        const cv::Rect full = cv::Rect(roi.x * scale, roi.y * scale, roi.width * scale,
                                       roi.height * scale) & image;
        cv::resize(inst.mask(full), region, roi.size(), 0, 0, cv::INTER_NEAREST);
      }
    }
    std::vector<cv::Point2f> from, to;
    if (!roi.empty()) {
      const double min_distance = std::max(2.0, 5.0 / scale);
      cv::goodFeaturesToTrack(last_gray_(roi), from, options_.max_corners, 0.01, min_distance,
                              region);
      const cv::Point2f origin(static_cast<float>(roi.x), static_cast<float>(roi.y));
      for (cv::Point2f& p : from) p += origin;
    }
    double dx = 0, dy = 0;
    if (!from.empty()) {
      std::vector<uchar> status;
      std::vector<float> err;
      cv::calcOpticalFlowPyrLK(last_pyramid_, pyramid, from, to, status, err, window, kLevels);
      std::vector<float> fx, fy;
      for (size_t i = 0; i < from.size(); ++i) {
        if (!status[i]) continue;
        fx.push_back(to[i].x - from[i].x);
        fy.push_back(to[i].y - from[i].y);
      }
      if (static_cast<int>(fx.size()) >= options_.min_tracked) {
        dx = scale * MedianOf(fx);
        dy = scale * MedianOf(fy);
      }
    }
    inst.mask = ShiftMask(inst.mask, dx, dy);
    inst.box = cv::Rect(cvRound(inst.box.x + dx), cvRound(inst.box.y + dy), inst.box.width,
                        inst.box.height) &
               image;
  }
  instances_.erase(std::remove_if(instances_.begin(), instances_.end(),
                                  [](const Instance& i) { return i.box.empty(); }),
                   instances_.end());  // moved out of view
  last_gray_ = small;
  last_pyramid_ = std::move(pyramid);
  std::vector<Instance> out = instances_;
  const int grow = options_.grow_px_per_frame * age_;
  for (Instance& inst : out) {
    inst.mask = Grow(inst.mask, grow);
    inst.box = cv::Rect(inst.box.x - grow, inst.box.y - grow, inst.box.width + 2 * grow,
                        inst.box.height + 2 * grow) &
               image;
  }
  return out;
}

}  // namespace detslam
