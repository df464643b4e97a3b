// ORB feature extractor in the style of ORB-SLAM3: an image pyramid, FAST corners per cell with a
// fall-back threshold, an even spatial spread by quadtree distribution, orientation by intensity
// centroid and 256-bit steered BRIEF (rBRIEF) descriptors on a Gaussian-blurred pyramid.
//
// The descriptor uses this project's own sampling pattern (see orb_pattern.h), not ORB's learned
// one, so descriptors are not interchangeable with ORB-SLAM3 / OpenCV ORB descriptors.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace detslam {

struct OrbOptions {
  int num_features = 1000;    // total keypoints over all levels
  double scale_factor = 1.2;  // pyramid scale between levels
  int num_levels = 8;         // pyramid levels
  int ini_th_fast = 20;       // FAST threshold tried first in each cell
  int min_th_fast = 7;        // FAST threshold for cells where the first finds nothing
  // Speed only, the result is the same: no low-threshold retry in a cell the ignore mask covers
  // entirely (every corner found there would be dropped). Off only to test that equality.
  bool skip_masked_cells = true;

  bool Check(std::string* error) const;
};

// The part of OrbExtractor::Extract that needs no mask (OrbExtractor::Prepare): the image pyramid,
// each level padded and blurred, and the FAST corners at the initial threshold over each level, so
// that it can be computed while the frame's masks are still being made (camera-rate mode).
struct OrbPyramid {
  struct Level {
    cv::Mat image;                     // the level
    cv::Mat padded;                    // with the edge border (orientation)
    cv::Mat blurred;                   // padded, Gaussian-blurred (descriptors)
    std::vector<cv::KeyPoint> strong;  // FAST at ini_th_fast, level pixels
  };
  cv::Size size;  // level 0's
  std::vector<Level> levels;
};

class OrbExtractor {
 public:
  // Throws InputError if the options do not pass Check().
  explicit OrbExtractor(const OrbOptions& options);

  // gray: CV_8UC1. ignore_mask: empty or CV_8UC1 of the same size, non-zero = ignore keypoints
  // there (they are dropped before distribution, so the budget goes to the rest of the image).
  // Keypoints are in level-0 pixel coordinates: pt, octave = level, angle in degrees [0, 360),
  // response = FAST score, size = patch size (31) * level scale. descriptors: CV_8UC1, N x 32.
  // Throws InputError on a wrong image type or mask size. Deterministic.
  void Extract(const cv::Mat& gray, const cv::Mat& ignore_mask,
               std::vector<cv::KeyPoint>* keypoints, cv::Mat* descriptors) const;
  // The same in two steps: Prepare (no mask; throws InputError on a wrong image type), then
  // Extract from its result (keypoints and descriptors identical to the one-step Extract's).
  OrbPyramid Prepare(const cv::Mat& gray) const;
  void Extract(const OrbPyramid& pyramid, const cv::Mat& ignore_mask,
               std::vector<cv::KeyPoint>* keypoints, cv::Mat* descriptors) const;

  int num_levels() const { return options_.num_levels; }
  const std::vector<double>& scale_factors() const { return scale_factors_; }  // 1, 1.2, ...
  const std::vector<double>& level_sigma2() const { return level_sigma2_; }    // scale^2
  const std::vector<double>& inv_level_sigma2() const { return inv_level_sigma2_; }
  const OrbOptions& options() const { return options_; }
  // Target keypoint count per level (geometric series, remainder to the top level).
  const std::vector<int>& features_per_level() const { return features_per_level_; }

 private:
  OrbOptions options_;
  std::vector<double> scale_factors_;
  std::vector<double> inv_scale_factors_;
  std::vector<double> level_sigma2_;
  std::vector<double> inv_level_sigma2_;
  std::vector<int> features_per_level_;
};

// Hamming distance between two 32-byte (256-bit) descriptors.
int DescriptorDistance(const uint8_t* a, const uint8_t* b);

}  // namespace detslam
