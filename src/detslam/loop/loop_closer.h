// Loop closing for RGB-D: after local mapping of a keyframe, look for an older keyframe of the
// same place that is not in its covisibility neighbourhood, verify the loop geometrically (3-D to
// 3-D rigid RANSAC on descriptor matches with the keyframe's depth, then pose-only optimisation
// with more matches by projection), fuse the duplicated landmarks, and distribute the correction
// over the map by a pose-graph optimisation (spanning tree, strong covisibility edges, loop edges;
// ORB-SLAM's essential graph), moving every landmark with its reference keyframe. The bundle
// adjustment of the whole map that follows (global_ba_iterations) is the caller's step, outside
// the map lock (mapping/map_bundle.h GlobalBundleAdjustment).
//
// Candidates: with a vocabulary (keyframes carry bag-of-words vectors), by appearance among the
// keyframes that are neither covisible with the new one nor among its `min_keyframe_gap` newest
// (place_candidates.h), accepted once consistent over `consistent_detections` consecutive
// keyframes; `candidate_radius_m` > 0 adds a position gate (candidate centre within that distance
// of the new keyframe's). Without a vocabulary: the keyframes within `candidate_radius_m`, nearest
// first (needs a radius > 0).
#pragma once

#include <map>
#include <string>
#include <vector>

#include "detslam/core/camera.h"
#include "detslam/core/rng.h"
#include "detslam/map/map.h"
#include "detslam/map/place_candidates.h"

namespace detslam {

struct LoopClosingOptions {
  bool enabled = true;
  int min_keyframe_gap = 20;        // candidates at least this many keyframe ids older
  double candidate_radius_m = 0.0;  // > 0: candidate keyframe centres within this distance
  int consistent_detections = 3;    // consecutive keyframes a candidate group must persist
  int max_candidates = 8;           // examined per keyframe (nearest first)
  int min_matches = 40;             // descriptor matches with depth to try RANSAC
  double ransac_inlier_m = 0.05;    // 3-D inlier distance (scaled by depth / 2 m, at least this)
  int min_ransac_inliers = 30;
  int min_verified_inliers = 80;   // pose-only inliers after the projection search
  int essential_min_weight = 100;  // covisibility edges kept in the pose graph
  int global_ba_iterations =
      10;  // bundle adjustment of the whole map after the pose graph (0: none; run by the caller)
  uint64_t seed = 7;  // RANSAC
  bool Check(std::string* error) const;
};

struct LoopClosingResult {
  bool closed = false;
  KeyFrameId keyframe = kNoKeyFrame;   // the keyframe that closed the loop
  KeyFrameId candidate = kNoKeyFrame;  // the older keyframe of the same place
  int inliers = 0;                     // verified pose-only inliers
  int fused = 0;                       // landmarks merged
  double correction_m = 0;             // how far the keyframe moved
  // Keyframe poses before the correction (cam_from_world), for the tracker and the trajectory.
  std::map<KeyFrameId, Rigid3d> old_poses;
};

class LoopCloser {
 public:
  LoopCloser(const PinholeCamera& camera, LoopClosingOptions options);

  // Looks for and closes a loop at keyframe `kf` of `map` (the caller holds the map store's write
  // access for the whole step). Deterministic.
  LoopClosingResult Process(Map& map, KeyFrameId kf);

  int loops_closed() const { return loops_closed_; }

 private:
  struct Verified {
    KeyFrameId candidate = kNoKeyFrame;
    Rigid3d cam_from_world;           // corrected pose of the current keyframe
    std::vector<LandmarkId> matched;  // per keypoint of the current keyframe
    // Landmarks of the candidate's neighbourhood, to fuse into the current keyframe's.
    std::vector<LandmarkId> loop_landmarks;
    int inliers = 0;
  };
  bool WithinRadius(const Map& map, KeyFrameId kf, KeyFrameId other) const;
  std::vector<KeyFrameId> CandidatesByPosition(const Map& map, KeyFrameId kf) const;
  std::vector<KeyFrameId> CandidatesByAppearance(const Map& map, KeyFrameId kf);
  bool Verify(const Map& map, KeyFrameId kf, KeyFrameId candidate, Verified* out);
  void Correct(Map& map, KeyFrameId kf, const Verified& loop, LoopClosingResult* result);

  PinholeCamera camera_;
  LoopClosingOptions options_;
  Rng rng_;
  LoopConsistency consistency_;
  KeyFrameId last_loop_kf_ = kNoKeyFrame;
  int loops_closed_ = 0;
};

}  // namespace detslam
