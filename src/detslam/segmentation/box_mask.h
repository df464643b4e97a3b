// Masks for detections without a mask model: the box pixels at the object's dominant depth.
// Also small box/mask helpers shared by the backends and their tests.
#pragma once

#include <opencv2/core.hpp>
#include <string>

namespace detslam {

struct DominantDepthOptions {
  double bin_m = 0.05;        // histogram bin width (metres)
  double tolerance_m = 0.30;  // keep pixels within +-tolerance of the dominant depth (metres)
  int min_valid_pixels = 20;  // fewer valid depths in the box than this -> whole-box mask
  double min_depth_m = 0.1;   // depths outside [min, max] count as missing (metres)
  double max_depth_m = 10.0;

  bool Check(std::string* error) const;
};

// `box` grown by `fraction` of its width/height on every side (0.1 = 10% each side), clipped to
// an image of `size`.
cv::Rect ExpandBox(const cv::Rect& box, double fraction, const cv::Size& size);

// Full-image CV_8UC1 mask (255 = object) of the pixels of `box` (clipped to the image) that lie at
// the object's dominant depth: a histogram of the valid depths inside the box (bins of bin_m from
// the smallest valid depth) is smoothed over 3 neighbouring bins; its highest bin (the nearer one
// on ties) gives the dominant depth d* (mean of the depths in that bin); pixels with
// |depth - d*| <= tolerance_m are kept. Pixels without depth are not part of the mask. With no
// depth image (empty) or too few valid depths the mask is the whole box.
cv::Mat DominantDepthBoxMask(const cv::Mat& depth_m, const cv::Rect& box, const cv::Size& size,
                             const DominantDepthOptions& options);

// The mask of a person: `model_mask` (full-image CV_8UC1 from a person mask model) when it covers
// at least `min_fill` of `box`, else DominantDepthBoxMask (the model failed on this crop, e.g. a
// portrait model on a close-up torso without a face).
cv::Mat PersonMaskOrDepth(const cv::Mat& model_mask, const cv::Rect& box, double min_fill,
                          const cv::Mat& depth_m, const DominantDepthOptions& options);

// Intersection over union of two binary masks (non-zero = set); 0 if both are empty.
double MaskIou(const cv::Mat& a, const cv::Mat& b);

// Intersection over union of two boxes; 0 if both are empty.
double BoxIou(const cv::Rect& a, const cv::Rect& b);

}  // namespace detslam
