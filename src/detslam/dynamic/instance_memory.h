// Carries dynamic instances forward when the detector loses them (a person the detector misses
// for a frame or two is still moving): an instance of the previous frames that no current instance
// overlaps (box IoU below `min_iou`) is re-used, box and mask unchanged, for at most `max_age`
// frames. Frames must be fed in order.
//
// Depth tracking (`depth_track_age` > 0): detectors lose people for much longer where only a
// slice or a close-up torso shows (entering or leaving the view, or filling half of it), and a
// tracker that then takes their keypoints for static ones follows them. A lost instance with a
// mask is instead followed in the depth image, for at most `depth_track_age` frames: its new mask
// is the connected region of pixels whose depth lies in the instance's depth band (the dominant
// depth mode of its previous mask's pixels in the new depth image, as the filter's depth step
// takes it, widened by DepthTrack::kBandMarginM) inside its box widened by
// DepthTrack::kGrowFraction, the component that overlaps its previous mask most; it stops when that
// region keeps less than DepthTrack::kMinAreaRatio or grows beyond DepthTrack::kMaxAreaRatio of
// the previous mask (the person has left or merged with the background) and then falls back to the
// plain carry above.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "detslam/segmentation/segmenter.h"

namespace detslam {

struct DepthTrack {
  static constexpr double kGrowFraction = 0.25;  // box widened by this fraction of its size per side
  static constexpr double kBandMarginM = 0.10;   // depth band widened by this much on each side
  static constexpr double kMinAreaRatio = 0.5;   // new mask area / previous, lowest accepted
  static constexpr double kMaxAreaRatio = 1.6;   // ... highest accepted

  // The instance's mask followed into `depth_m` (CV_32FC1 metres, 0 = missing): the updated
  // instance, or false when it cannot be followed (no mask, no depth, region too small or large).
  static bool Follow(const Instance& previous, const cv::Mat& depth_m, Instance* followed);
};

class InstanceMemory {
 public:
  // A remembered instance counts as found again when a current one overlaps it by this IoU.
  static constexpr double kDefaultMinIou = 0.3;
  explicit InstanceMemory(int max_age, double min_iou = kDefaultMinIou, int depth_track_age = 0)
      : max_age_(max_age), depth_track_age_(depth_track_age), min_iou_(min_iou) {}

  // Returns `current` plus remembered instances that are not covered by it. `depth_m` (may be
  // empty: no depth tracking) is the frame's depth, CV_32FC1 metres. `frames_elapsed`: frames since
  // the previous call (the segmenter may run on every k-th frame only); depth_track_age counts
  // frames, max_age counts calls.
  std::vector<Instance> Update(const std::vector<Instance>& current, const cv::Mat& depth_m = {},
                               int frames_elapsed = 1);

 private:
  struct Remembered {
    Instance instance;
    int age = 0;     // calls since it was last detected
    int frames = 0;  // frames since it was last detected
    bool depth_tracked = false;  // followed in depth since it was lost (else carried unchanged)
  };
  int max_age_;
  int depth_track_age_;
  double min_iou_;
  std::vector<Remembered> remembered_;
};

}  // namespace detslam
