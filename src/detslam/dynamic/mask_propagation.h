// Carries instance masks from a segmented frame to the following frames without running the
// segmenter ("segment every k-th frame"): each instance's mask and box move with the median
// optical flow (pyramidal Lucas-Kanade) of corners tracked inside the mask from the previous
// frame, and the mask grows by a few pixels per frame of age to cover what the median flow misses
// (limbs, the parts of a person turning). Frames must be fed in order.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "detslam/segmentation/segmenter.h"

namespace detslam {

struct MaskPropagationOptions {
  int max_corners = 80;       // corners tracked per instance
  // Mask dilation added per frame since the last segmentation (Segmentation.CarryGrowth). 0
  // chosen on the tuning seeds (docs/STATUS.md, 2026-12-07): the ring a growing mask withholds
  // around each person cost more than the limbs it catches (the geometric check and the robust
  // pose take those); 2 before.
  int grow_px_per_frame = 0;
  int min_tracked = 3;  // fewer tracked corners: the instance keeps its place (still grown)
  // The optical flow runs on the images reduced by this factor (1, 2 or 4; each halving is a
  // cv::pyrDown), with the window reduced with them and the same 3 pyramid levels, so that the
  // search reaches as far in full-resolution pixels; the median flow is scaled back. A person's
  // shift needs no full-resolution flow: the mask moves by whole pixels (and grew
  // 2 px per frame when this was chosen). 2 chosen on the
  // tuning seeds (docs/STATUS.md): carried masks as complete as with 1, the carry 2.5x faster.
  int flow_scale = 2;
  bool Check(std::string* error) const;
};

class MaskPropagator {
 public:
  explicit MaskPropagator(MaskPropagationOptions options = {});

  // A segmented frame: its grey image (CV_8UC1) and instances become the new reference.
  void Reset(const cv::Mat& gray, std::vector<Instance> instances);
  // A frame without segmentation: the last frame's instances moved into `gray`, which comes
  // `frames` (>= 1) input frames after the last one (frames dropped in between count: the masks
  // grow with the time elapsed). Empty before the first Reset.
  std::vector<Instance> Propagate(const cv::Mat& gray, int frames = 1);

  // Input frames since the last Reset (0 right after it).
  int age() const { return age_; }

 private:
  MaskPropagationOptions options_;
  // `gray` reduced by options_.flow_scale.
  cv::Mat Reduced(const cv::Mat& gray) const;

  cv::Mat last_gray_;                  // reduced by options_.flow_scale
  std::vector<cv::Mat> last_pyramid_;  // of last_gray_, built on first use
  cv::Size full_size_;               // of the images, before reduction
  std::vector<Instance> instances_;  // in the full-size image of last_gray_, not yet grown
  int age_ = 0;
};

// The whole-pixel shift cv::warpAffine with INTER_NEAREST makes of a translation by `d` pixels:
// the nearest integer, halves rounded down (its 10-bit fixed point).
int NearestShift(double d);

// Shifts a CV_8UC1 mask by (dx, dy) pixels (zeros enter at the borders): NearestShift of each,
// equal to cv::warpAffine(INTER_NEAREST) of the translation pixel for pixel.
cv::Mat ShiftMask(const cv::Mat& mask, double dx, double dy);

}  // namespace detslam
