// One RGB-D frame after feature extraction: keypoints (distorted as detected, and undistorted),
// their depth and virtual right coordinate, descriptors, a grid for area queries, and the
// per-keypoint associations to map landmarks that tracking fills in.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "detslam/core/camera.h"
#include "detslam/core/rigid3d.h"
#include "detslam/core/timestamp.h"
#include "detslam/features/keypoint_grid.h"
#include "detslam/place/bow_vector.h"
#include "detslam/place/vocabulary.h"

namespace detslam {

using LandmarkId = int64_t;
using KeyFrameId = int64_t;
constexpr LandmarkId kNoLandmark = -1;
constexpr KeyFrameId kNoKeyFrame = -1;

// Why a keypoint was withheld from tracking (diagnostics for the dynamic filter).
enum class KeypointLabel : uint8_t {
  kStatic = 0,
  kDynamicMask = 1,
  kDynamicDepth = 2,
  kGeometric = 3
};

// Scale pyramid facts shared by all frames of a run.
struct ScaleInfo {
  std::vector<double> scale_factors;     // per level: 1, s, s^2, ...
  std::vector<double> level_sigma2;      // scale^2
  std::vector<double> inv_level_sigma2;  // 1 / scale^2
  double log_scale_factor = 0.0;         // log(s)
  int num_levels() const { return static_cast<int>(scale_factors.size()); }
  // The pyramid of `num_levels` levels with factor `scale_factor` (sigma of a level = its scale).
  static ScaleInfo Geometric(double scale_factor, int num_levels);
};

struct FrameFeatures {
  std::vector<cv::KeyPoint> keypoints;  // as detected (distorted pixel coordinates)
  std::vector<Eigen::Vector2d> undist;  // undistorted pixel coordinates
  std::vector<float> depth;             // metres, <= 0 when unknown
  std::vector<float> u_right;           // u - bf/depth, < 0 when unknown
  cv::Mat descriptors;                  // N x 32, CV_8UC1
  // Keypoints the Det-SLAM stage rejected, with their labels, kept for diagnostics only (tracking
  // never sees them; every keypoint above is static as far as the segmenter knows).
  std::vector<cv::KeyPoint> rejected_keypoints;
  std::vector<KeypointLabel> rejected_labels;
  std::shared_ptr<const KeypointGrid> grid;  // area queries over `undist`
  // Bag-of-words vector of the descriptors and their direct index (vocabulary nodes
  // kDirectIndexDepth below the root); both empty when the run has no vocabulary.
  BowVector bow;
  FeatureVector bow_nodes;

  size_t size() const { return keypoints.size(); }
  const uint8_t* Descriptor(size_t i) const {
    return descriptors.ptr<uint8_t>(static_cast<int>(i));
  }
};

struct Frame {
  int64_t index = 0;  // position in the input sequence
  Timestamp stamp;
  std::shared_ptr<const FrameFeatures> features;  // shared with the keyframe made from it
  std::vector<LandmarkId> landmarks;              // per keypoint, kNoLandmark if none
  std::vector<bool> outlier;                      // per keypoint, set by pose optimisation
  // Per keypoint, set by tracking: kGeometric where the geometric check found a mover the
  // segmenter missed (never used for new landmarks or frame-to-frame points); else kStatic.
  std::vector<KeypointLabel> labels;
  std::optional<Rigid3d> cam_from_world;
  KeyFrameId reference_keyframe = kNoKeyFrame;
  // CV_8UC1 in detected (distorted) pixels, non-zero where keypoints were withheld before
  // tracking (the Det-SLAM stage's dynamic regions, the run's ignore mask); empty: nowhere. A map
  // point seen there is hidden, not missed (tracking does not count it as visible).
  cv::Mat withheld;

  size_t size() const { return features ? features->size() : 0; }
};

// Depth below the vocabulary's root of the direct-index nodes (ORB-SLAM: 4 levels up of 6; with
// k = 10 up to 100 nodes, so that a matching candidate set holds about 1% of the keypoints).
constexpr int kDirectIndexDepth = 2;

// Fills features->bow and features->bow_nodes from its descriptors.
void ComputeFrameBow(const Vocabulary& vocabulary, FrameFeatures* features);

// Bounds of undistorted keypoint positions (the image corners undistorted).
ImageBounds UndistortedBounds(const PinholeCamera& camera);

// The area grid over a frame's undistorted keypoints (`keypoints` give the octaves), bounded by
// the undistorted image.
std::shared_ptr<const KeypointGrid> MakeKeypointGrid(const PinholeCamera& camera,
                                                     const std::vector<cv::KeyPoint>& keypoints,
                                                     const std::vector<Eigen::Vector2d>& undist);

// Each keypoint's depth from the depth image (CV_32FC1, metres; may be empty), read at the
// detected (distorted) pixel (lround(x), lround(y)) as ORB-SLAM does; -1 where missing, zero or
// not finite.
std::vector<float> SampleKeypointDepth(const std::vector<cv::KeyPoint>& keypoints,
                                       const cv::Mat& depth_m);

// Builds a frame's features from extraction output and each keypoint's depth (metres, <= 0
// unknown; as SampleKeypointDepth reads it): keypoints are undistorted, u_right = u - bf / depth.
std::shared_ptr<FrameFeatures> BuildFrameFeatures(const PinholeCamera& camera,
                                                  std::vector<cv::KeyPoint> keypoints,
                                                  cv::Mat descriptors, std::vector<float> depth);

}  // namespace detslam
