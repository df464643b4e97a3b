// The Det-SLAM dynamic filter: labels ORB keypoints that lie on (or at the depth of) dynamic
// objects found by the segmenter. Keypoints, not pixels: the image is never modified; rejected
// keypoints stay in the frame with a non-static label and the tracker ignores them.
//
// Two steps per dynamic instance (class in `dynamic_classes`, score >= `min_score`):
//  1. Mask step: a keypoint inside the instance mask dilated by `mask_dilation_px` is
//     kDynamicMask (an instance without a mask uses its box as the mask).
//  2. Depth step (Det-SLAM eqs. 1-6): inside the instance box, with
//       m_obj, M_obj = min, max depth of the object's mask pixels (dominant depth mode only),
//       d = M_roi - m_roi = max - min valid depth over the whole box,
//     every keypoint in the box whose depth lies in [m_obj - alpha*d, M_obj + alpha*d] is
//     kDynamicDepth (unless already kDynamicMask). Keypoints without depth stay static.
//
// Dominant mode (to ignore background pixels leaking into the mask): a histogram of the mask
// pixels' valid depths with bins of `depth_bin_m`; the most populated bin (ties: the nearer bin)
// is grown to the contiguous run of populated bins around it (a bin is populated when it holds at
// least `mode_min_bin_fraction` of the dominant bin's count, and at least one pixel); of the depths
// in that run, only those within +-`mode_window_m` of the dominant bin's centre are kept. The
// contiguous run separates the object from a background behind a depth gap; the window bounds the
// mode where flying pixels or a floor would otherwise bridge the gap. m_obj/M_obj are the min/max
// of the kept depths.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "detslam/map/frame.h"
#include "detslam/segmentation/segmenter.h"

namespace detslam {

struct DynamicFilterOptions {
  std::vector<std::string> dynamic_classes = DefaultDynamicClasses();  // treated as dynamic
  float min_score = 0.0f;                                 // ignore instances below this score
  int mask_dilation_px = 15;   // dilate masks by the ORB patch radius: descriptors of corners
                               // closer than that to a person sample the person's pixels
  bool depth_step = true;      // the paper's depth-ROI step
  double alpha = 0.1;          // widening factor of the depth interval (paper's alpha)
  double depth_bin_m = 0.05;   // histogram bin for the dominant depth mode of the object
  double mode_window_m = 0.5;  // the object's depth extent kept around its dominant mode (+-)
  double mode_min_bin_fraction = 0.02;  // bins below this fraction of the mode's count end the mode
  // m_obj/M_obj from the dominant depth mode (true) or, as the paper writes it, the raw min/max
  // over every mask pixel with depth (false; mask pixels on the background then widen the
  // interval to the background's depth).
  bool dominant_mode = true;

  bool Check(std::string* error) const;
  bool IsDynamicClass(const std::string& class_name) const;
  // Whether the filter acts on the instance: a dynamic class, scored at least min_score.
  bool Uses(const Instance& instance) const;
};

struct DynamicFilterStats {
  int instances_used = 0;  // dynamic instances at or above min_score
  int rejected_mask = 0;   // keypoints labelled kDynamicMask
  int rejected_depth = 0;  // keypoints labelled kDynamicDepth
};

// Min and max of the depths in the dominant mode (see the header comment).
struct DepthRange {
  bool valid = false;  // false when there is no valid (> 0, finite) depth
  double min = 0.0;
  double max = 0.0;
};

// The dominant depth mode of `depths` (metres; values <= 0 or non-finite are ignored).
DepthRange DominantDepthMode(const std::vector<float>& depths, double bin_m, double window_m,
                             double min_bin_fraction);

// The depth interval of one instance.
struct DepthInterval {
  double m_obj = 0.0;  // min depth of the object's mask pixels (dominant mode, or all of them)
  double M_obj = 0.0;  // max depth of the object's mask pixels (dominant mode, or all of them)
  double d_roi = 0.0;  // max - min valid depth over the whole box
  double lo = 0.0;     // m_obj - alpha * d_roi
  double hi = 0.0;     // M_obj + alpha * d_roi
  bool valid = false;  // false when the mask has no valid depth inside the box
  bool Contains(double depth) const { return valid && depth > 0.0 && depth >= lo && depth <= hi; }
};

// The instance's depth interval. `depth_m`: CV_32FC1 metres (0 = missing). `mask`: CV_8UC1 of the
// depth image's size, or empty (the box is the mask). Only pixels inside `box` (clipped to the
// image) count, for the object as well as for the box span.
DepthInterval ObjectDepthInterval(const cv::Mat& depth_m, const cv::Mat& mask, const cv::Rect& box,
                                  const DynamicFilterOptions& options);

// The dynamic instances of one frame rasterised once (dilated masks, clipped boxes, depth
// intervals), for both forms of the filter: the pixel mask handed to the ORB extractor and the
// keypoint labels.
class DynamicRegions {
 public:
  struct Region {
    cv::Rect roi;            // where `dilated` lies in the image
    cv::Mat dilated;         // CV_8UC1, roi-sized, non-zero = inside the dilated mask
    cv::Rect box;            // the instance box clipped to the image
    DepthInterval interval;  // invalid when the depth step is off or has no depth
  };

  // The regions of the instances of a dynamic class with score >= min_score. `depth_m`: CV_32FC1
  // metres, 0 = missing, of `image_size`; may be empty (then only the mask step runs). Throws
  // InputError when an instance mask is neither empty nor CV_8UC1 of `image_size`.
  static DynamicRegions Build(const std::vector<Instance>& instances, const cv::Mat& depth_m,
                              const cv::Size& image_size, const DynamicFilterOptions& options);

  // Labels each keypoint (labels->size() == keypoints.size(); existing non-static labels are
  // kept). A keypoint's pixel is (lround(x), lround(y)); `keypoint_depth`: metres, <= 0 unknown.
  DynamicFilterStats Label(const std::vector<cv::KeyPoint>& keypoints,
                           const std::vector<float>& keypoint_depth,
                           std::vector<KeypointLabel>* labels) const;
  // The same decision as a pixel mask (CV_8UC1, 255 = reject keypoints here), for the ORB
  // extractor to drop corners before its spatial distribution. `depth_m`: the image Build saw.
  // A keypoint whose depth is the depth image's value at its pixel is labelled by Label iff this
  // mask is non-zero there.
  cv::Mat IgnoreMask(const cv::Mat& depth_m) const;

 private:
  cv::Size image_size_;
  std::vector<Region> regions_;
  int instances_used_ = 0;
};

// One-shot forms (regions built for one call):
// Labels each keypoint (labels->size() == keypoints.size(), initialised by the caller to kStatic;
// existing non-static labels are kept). A keypoint's pixel is (lround(x), lround(y)).
// `keypoint_depth`: metres per keypoint, <= 0 unknown. `depth_m`: CV_32FC1 metres, 0 = missing; may
// be empty (then only the mask step runs). Throws InputError when an instance mask is neither empty
// nor CV_8UC1 of the depth image's size.
DynamicFilterStats LabelDynamicKeypoints(const std::vector<cv::KeyPoint>& keypoints,
                                         const std::vector<float>& keypoint_depth,
                                         const std::vector<Instance>& instances,
                                         const cv::Mat& depth_m,
                                         const DynamicFilterOptions& options,
                                         std::vector<KeypointLabel>* labels);

// The same decision as a pixel mask (CV_8UC1 of `image_size`, 255 = reject keypoints here).
cv::Mat DynamicIgnoreMask(const std::vector<Instance>& instances, const cv::Mat& depth_m,
                          const cv::Size& image_size, const DynamicFilterOptions& options);

}  // namespace detslam
