// Descriptor matching guided by geometry: project landmarks (or the previous frame's points) into
// a frame with a predicted pose and pick the best keypoint in a window around the projection,
// ORB-SLAM style (scale prediction, viewing-angle check, ratio test, rotation consistency).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "detslam/map/map.h"

namespace detslam {

// A 3-D point with a descriptor, to be matched into a frame.
struct ProjectionCandidate {
  LandmarkId landmark = kNoLandmark;  // kNoLandmark for temporary (frame-to-frame) points
  Eigen::Vector3d position;           // world frame
  const uint8_t* descriptor = nullptr;
  int predicted_level = -1;                          // < 0: predict from distance bounds
  double min_distance = 0, max_distance = 0;         // 0: no scale check
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // zero: no viewing-angle check
  float source_angle = -1;  // keypoint angle in the source image (< 0: none)
};

struct ProjectionSearchOptions {
  double window = 3.0;             // search radius in pixels at level 0 (scaled by level)
  double ratio = 0.8;              // best/second-best ratio (applied only within the same level)
  int max_distance = 100;          // descriptor distance threshold (TH_HIGH)
  bool check_orientation = false;  // rotation-consistency histogram (needs source_angle)
  bool level_window_from_prediction = true;  // search levels [pred-1, pred]
};

// Candidate for a map landmark (position, representative descriptor, scale bounds, normal).
ProjectionCandidate CandidateFromLandmark(const Landmark& landmark);

// True for keypoints of `frame` already associated with a landmark.
std::vector<bool> TakenMask(const Frame& frame);

// How MatchKeyFrameLandmarks pairs descriptors.
enum class DescriptorSearch {
  kBruteForce,      // every landmark-bearing keypoint of the keyframe against every keypoint
  kVocabularyNode,  // only within the same direct-index node (both need bow_nodes)
};

// Descriptor matching of a keyframe's landmark-bearing keypoints against a frame (MatchWithinGroups
// rules, orientation check on): returns, per frame keypoint, the matched landmark (kNoLandmark
// where none). kVocabularyNode needs both sides' bag-of-words direct index (an empty one matches
// nothing).
std::vector<LandmarkId> MatchKeyFrameLandmarks(
    const KeyFrame& keyframe, const FrameFeatures& frame, double ratio, int max_distance,
    DescriptorSearch search = DescriptorSearch::kBruteForce);

// MatchKeyFrameLandmarks against several keyframes in turn (e.g. a place candidate and its best
// covisibles, as ORB-SLAM3 matches a loop candidate's window): a frame keypoint keeps the first
// landmark it matched, and a landmark is matched to at most one keypoint.
std::vector<LandmarkId> MatchKeyFramesLandmarks(
    const std::vector<const KeyFrame*>& keyframes, const FrameFeatures& frame, double ratio,
    int max_distance, DescriptorSearch search = DescriptorSearch::kBruteForce);

// For each candidate, the index of the matched keypoint in `features` (or -1). Keypoints listed in
// `taken` (same size as features; true = already associated) are skipped. Deterministic.
std::vector<int> SearchByProjection(const PinholeCamera& camera, const ScaleInfo& scale,
                                    const FrameFeatures& features, const Rigid3d& cam_from_world,
                                    const std::vector<ProjectionCandidate>& candidates,
                                    const std::vector<bool>& taken,
                                    const ProjectionSearchOptions& options);

}  // namespace detslam
