// Frame-to-map tracking for RGB-D (ORB-SLAM3 rules, see docs/ARCHITECTURE.md): map
// initialisation from the first frame with depth, motion-model tracking against the previous
// frame (with temporary points from its depth), reference-keyframe tracking, local-map tracking,
// the keyframe decision, and relocalisation by PnP RANSAC when lost.
#pragma once

#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "detslam/core/rng.h"
#include "detslam/dynamic/geometric_check.h"
#include "detslam/map/map.h"
#include "detslam/optim/pose_optimizer.h"

namespace detslam {

enum class TrackingState { kNotInitialized, kOk, kRecentlyLost, kLost };
const char* ToString(TrackingState state);

struct TrackerOptions {
  int min_init_keypoints = 500;        // keypoints with depth needed to initialise
  double motion_window = 7.0;          // projection window, motion model (RGB-D: 7 px at level 0)
  double local_map_window = 3.0;       // projection window for local map points
  int min_motion_matches = 20;         // else retry with twice the window
  int min_pose_inliers = 10;           // motion-model / reference-keyframe success
  int min_local_map_inliers = 30;      // TrackLocalMap success (50 right after relocalisation)
  int max_local_keyframes = 80;        // local map size
  int temporary_points_min = 100;      // frame-to-frame points from the last frame's depth
  int keyframe_far_points = 300;       // landmarks from depth per keyframe beyond ThDepth (see docs)
  double recently_lost_seconds = 3.0;  // then LOST
  int max_frames_between_keyframes = 30;  // mMaxFrames (= fps)
  double ref_ratio = 0.75;             // thRefRatio (0.4 with one keyframe)
  int close_tracked_max = 100;         // bNeedToInsertClose: tracked close < this
  int close_untracked_min = 70;        //                      and untracked close > this
  uint64_t seed = 42;                  // relocalisation RANSAC
  // Geometric check for movers the segmenter missed (see tracker_geometric.cc). On by default: it
  // lowered the error on the walking presets where the detector misses partly visible people and
  // changed nothing on the static benchmarks (docs/BENCHMARKS.md).
  bool geometric_check = true;
  GeometricCheckOptions geometric;     // robust threshold on reprojection residuals (pixels / scale)
  double geometric_radius_px = 30.0;   // cluster / spread radius around a flagged keypoint
  double geometric_depth_ratio = 0.1;  // same object: depths within this fraction
  int geometric_min_cluster = 3;       // flagged neighbours needed to confirm a mover
  double geometric_carry_window = 15.0;  // search window for last frame's movers (pixels, level 0)
  bool Check(std::string* error) const;
};

struct TrackingResult {
  TrackingState state = TrackingState::kNotInitialized;
  bool pose_valid = false;       // frame has a pose (state OK this frame)
  bool need_keyframe = false;
  bool relocalized = false;
  int num_inliers = 0;           // landmark inliers after local-map tracking
  int geometric_rejected = 0;    // keypoints the geometric check labelled kGeometric
  std::string method;            // "init", "motion", "reference", "relocalization", "lost"
};

class Tracker {
 public:
  Tracker(const PinholeCamera& camera, TrackerOptions options, Map* map);

  // Tracks `frame` (its features must be set). Fills frame->cam_from_world, landmarks, outliers,
  // reference_keyframe. Creates the first keyframe on initialisation.
  TrackingResult Track(Frame* frame);

  // Turns the current frame into a keyframe: links its inlier landmarks, creates landmarks from
  // close depth (ORB-SLAM's CreateNewKeyFrame for RGB-D). Returns its id.
  KeyFrameId CreateKeyFrame(Frame* frame);

  TrackingState state() const { return state_; }
  // Reference keyframe of the last tracked frame.
  KeyFrameId reference_keyframe() const { return reference_kf_; }
  // Called by the mapper when a keyframe has been erased, so the tracker drops references.
  void OnKeyFrameErased(KeyFrameId id);
  // Called after loop closing moved the keyframes (`old_poses`: their poses before): moves the
  // last frame with its reference keyframe.
  void OnLoopClosed(const std::map<KeyFrameId, Rigid3d>& old_poses);

 private:
  bool Initialize(Frame* frame);
  bool TrackWithMotionModel(Frame* frame);
  bool TrackReferenceKeyFrame(Frame* frame);
  bool TrackLocalMap(Frame* frame, int* inliers);
  bool Relocalize(Frame* frame);
  bool NeedNewKeyFrame(const Frame& frame, int inliers) const;
  // Pose optimisation over the frame's matched landmarks and temporary points; marks outliers and
  // drops their associations. Returns the number of inliers.
  int OptimizeFramePose(Frame* frame, bool include_temporary);
  void BuildTemporaryPoints();
  // Labels movers the segmenter missed as kGeometric (after the final pose is known): matched
  // keypoints whose residual is far above the static ones' and confirmed by flagged neighbours,
  // unmatched keypoints next to them at the same depth, and keypoints matching the last frame's
  // movers. Drops their landmark associations and re-optimises the pose if any was an inlier.
  // Returns the number of labelled keypoints.
  int ApplyGeometricCheck(Frame* frame, int* inliers);
  void UpdateLocalMap(const Frame& frame);
  KeyFrameId CreateLandmarksFromDepth(Frame* frame, KeyFrameId kf_id);

  PinholeCamera camera_;
  TrackerOptions options_;
  Map* map_;
  Rng rng_;
  PoseOptimizerOptions pose_options_;
  TrackingState state_ = TrackingState::kNotInitialized;

  std::optional<Frame> last_frame_;
  std::vector<std::optional<Eigen::Vector3d>> temporary_points_;  // per last-frame keypoint
  std::optional<Rigid3d> velocity_;  // cam_from_world(k) * world_from_cam(k-1)
  KeyFrameId reference_kf_ = kNoKeyFrame;
  KeyFrameId last_keyframe_ = kNoKeyFrame;
  int64_t last_keyframe_frame_ = 0;
  int64_t last_reloc_frame_ = -1000000;
  Timestamp lost_since_;
  std::vector<KeyFrameId> local_keyframes_;
  std::vector<LandmarkId> local_landmarks_;
  std::vector<bool> temp_matched_;  // per current keypoint: matched to a temporary point
  std::vector<Eigen::Vector3d> temp_match_position_;
  // Per current keypoint: the point of an association the pose optimiser rejected (for the
  // geometric check's residuals).
  std::vector<bool> dropped_;
  std::vector<Eigen::Vector3d> dropped_position_;
};

}  // namespace detslam
