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

#include "detslam/core/id_stamps.h"
#include "detslam/core/rng.h"
#include "detslam/dynamic/geometric_check.h"
#include "detslam/dynamic/mover_check.h"
#include "detslam/map/map.h"
#include "detslam/optim/pose_optimizer.h"

namespace detslam {

enum class TrackingState { kNotInitialized, kOk, kRecentlyLost, kLost };
const char* ToString(TrackingState state);

struct TrackerOptions {
  int min_init_keypoints = 500;    // initialise from a frame with more keypoints than this
                                   // (ORB-SLAM3's N > 500, counted after the dynamic filter)
  int min_init_depth_keypoints = 100;  // ... of which at least this many have depth (the map)
  double motion_window = 7.0;      // projection window, motion model (RGB-D: 7 px at level 0)
  double local_map_window = 3.0;   // projection window for local map points
  int min_motion_matches = 20;     // else retry with twice the window
  int min_pose_inliers = 10;       // motion-model / reference-keyframe success
  int min_local_map_inliers = 30;  // TrackLocalMap success (50 right after relocalisation)
  int max_local_keyframes = 80;    // local map size
  int temporary_points_min = 100;  // frame-to-frame points from the last frame's depth
  int keyframe_far_points = 300;   // landmarks from depth per keyframe beyond ThDepth (see docs)
  double recently_lost_seconds = 3.0;     // then LOST
  int max_frames_between_keyframes = 30;  // mMaxFrames (= fps)
  double ref_ratio = 0.75;                // thRefRatio (0.4 with one keyframe)
  int close_tracked_max = 100;            // bNeedToInsertClose: tracked close < this
  int close_untracked_min = 70;           //                      and untracked close > this
  // Local-map points that project where the frame's keypoints were withheld (Frame::withheld:
  // people, the ignore mask) are hidden there, not missed: they are not searched and do not count
  // as visible for culling's found ratio. false: counted as ORB-SLAM3 counts every point in the
  // frustum.
  bool skip_withheld_points = true;
  // The close-point keyframe rule (tracked close < close_tracked_max) with the bound divided by
  // the fraction of the image where keypoints were not withheld (at least 0.3): a person hiding
  // the near scene leaves fewer close points to track, and then a keyframe is made sooner. Only
  // while local mapping is idle (always in sequential runs). false: ORB-SLAM3's fixed bound.
  bool keyframes_for_withheld = true;
  // Several maps: when a frame can neither be tracked nor relocalised, start a new map from it at
  // once (RGB-D initialises from one frame), so that no stretch is left without poses; the old
  // maps stay, relocalisation and loop closing search them too, and a verified overlap merges
  // them (loop/loop_closer.h). false: stay lost until relocalisation succeeds (one map).
  bool new_map_when_lost = true;
  uint64_t seed = 42;                     // relocalisation RANSAC
  bool Check(std::string* error) const;
};

// What the tracker knows of local mapping when it decides on a keyframe (ORB-SLAM3's
// AcceptKeyFrames and KeyframesInQueue). Sequential runs map each keyframe before the next frame:
// always idle there.
struct LocalMappingState {
  bool idle = true;  // no keyframe is being mapped or waits to be
  int queued = 0;    // keyframes waiting, not counting the one being mapped
};

struct TrackingResult {
  TrackingState state = TrackingState::kNotInitialized;
  bool pose_valid = false;  // frame has a pose (state OK this frame)
  bool need_keyframe = false;
  // The frame wanted a keyframe while local mapping was busy: stop its bundle adjustment, so
  // that it takes the new keyframes sooner (ORB-SLAM3's InterruptBA). need_keyframe may be false.
  bool interrupt_local_ba = false;
  bool relocalized = false;
  int num_inliers = 0;         // landmark inliers after local-map tracking
  int geometric_rejected = 0;  // keypoints the geometric check labelled kGeometric
  // "init", "motion", "reference", "relocalization", "new map", "lost"
  std::string method;
  bool new_map = false;  // this frame started a new map (after tracking was lost)
};

// The tracker borrows the map for each call: its callers hold the map store's write access (which
// also guards the tracker's own state, since the mapping thread calls OnKeyFrameErased and
// OnLoopClosed) and pass the map in.
class Tracker {
 public:
  // `movers`: the Det-SLAM stage's geometric check for movers the segmenter missed, run after
  // the pose is tracked (its options live in DetSlamOptions).
  Tracker(const PinholeCamera& camera, TrackerOptions options, MoverCheckOptions movers = {});

  // Tracks `frame` (its features must be set). Fills frame->cam_from_world, landmarks, outliers,
  // reference_keyframe. Creates the first keyframe on initialisation.
  // `mapping`: local mapping's state (threaded runs); while it is busy a keyframe is made only
  // when tracking needs one (ORB-SLAM3's c1a / c1c) and fewer than kMaxQueuedKeyFrames wait.
  TrackingResult Track(Map& map, Frame* frame, const LocalMappingState& mapping = {});

  // Turns the current frame into a keyframe: links its inlier landmarks, creates landmarks from
  // close depth (ORB-SLAM's CreateNewKeyFrame for RGB-D). Returns its id.
  KeyFrameId CreateKeyFrame(Map& map, Frame* frame);

  // Relocalisation alone, as Track does it when lost (for benchmarks and tests): bag-of-words
  // candidates (every keyframe, newest first, when the frame has no bag-of-words vector), matching,
  // PnP RANSAC and pose optimisation. On success sets frame->cam_from_world and landmarks and
  // returns the keyframe it relocalised against; else kNoKeyFrame. Changes the tracker's reference
  // keyframe and local map.
  KeyFrameId RelocalizeFrame(const Map& map, Frame* frame);

  TrackingState state() const { return state_; }
  // Reference keyframe of the last tracked frame.
  KeyFrameId reference_keyframe() const { return reference_kf_; }
  // Called by the mapper when a keyframe has been erased, so the tracker drops references.
  void OnKeyFrameErased(const Map& map, KeyFrameId id);
  // Called after loop closing moved the keyframes (`old_poses`: their poses before): moves the
  // last frame with its reference keyframe.
  void OnLoopClosed(const Map& map, const std::map<KeyFrameId, Rigid3d>& old_poses);
  // Asks for one keyframe as soon as max_frames_between_keyframes have passed since the last one,
  // even where the usual criteria would not take one (tracking still needs enough inliers): loop
  // closing asks while a verified loop waits for more keyframes to agree, which on a revisit of
  // well-tracked ground would otherwise come seconds apart.
  void RequestKeyFrame() { keyframe_requested_ = true; }
  // With a map loaded before the first frame: no initialisation, relocalise from the first frame.
  void StartInLoadedMap() { state_ = TrackingState::kLost; }

 private:
  // ORB-SLAM3's fixed tracking thresholds (Tracking.cc, RGB-D), named.
  static constexpr size_t kLocalMapCovisibles =
      10;  // UpdateLocalKeyFrames: best covisibles per K1 keyframe
  static constexpr int kMinReferenceMatches = 15;  // TrackReferenceKeyFrame: BoW matches needed
  static constexpr double kReferenceRatio = 0.7;   //   and its matcher's nearest-neighbour ratio
  static constexpr double kMotionRatio = 0.9;      // TrackWithMotionModel's matcher ratio
  static constexpr double kLocalMapRatio = 0.8;    // SearchLocalPoints' matcher ratio
  static constexpr double kRelocLocalMapWindow =
      5.0;  // SearchLocalPoints' window right after relocalisation
  static constexpr size_t kMinRelocalizationMatches =
      15;  // Relocalization: candidate keyframe matches
  static constexpr double kRelocalizationRatio = 0.75;  //   and its matcher's ratio
  static constexpr int kRelocalizationWindowKeyFrames = 5;  // covisibles added when too few
  static constexpr int kMinRelocalizationPnpInliers =
      10;                                            // PnP + pose optimisation inliers to go on
  static constexpr int kRelocalizationInliers = 50;  // inliers that accept a relocalisation; also
                                                     // TrackLocalMap's need right after one
  // A relocalisation that reached kRelocalizationInliers only through the projection search is
  // accepted when its PnP consensus was strong or its pose explains a fair share of what the map
  // shows there: look-alike places (same textures, another layout) give a few consistent matches
  // that the wide projection search then inflates, matching a small share of the points in view.
  // Not ORB-SLAM3's rule (which accepts on the count alone); chosen on tuning seeds
  // (docs/STATUS.md).
  static constexpr int kRelocalizationStrongPnpInliers = 20;  // before the projection search
  static constexpr double kRelocalizationMinViewShare = 0.10;  // inliers / local-map points in view
  static constexpr double kRelocalizationWindow =
      10;  // projection search widening a relocalisation
  static constexpr double kRelocalizationProjectionRatio = 0.9;
  static constexpr int kMinKeyFrameInliers = 15;  // NeedNewKeyFrame c2: at least this many inliers
  // keyframes_for_withheld: the visible fraction the close-point bound is divided by, at least.
  static constexpr double kMinVisibleForCloseRule = 0.3;
  static constexpr int kMaxQueuedKeyFrames = 3;   // ... and, mapping busy, fewer waiting (RGB-D)
  static constexpr double kNewKeyFrameRefRatioOneKf = 0.4;  // thRefRatio with one keyframe
  static constexpr double kNewKeyFrameLowRatio = 0.25;  // c1c: weak tracking against the reference

  // Per-keypoint state of the frame being tracked, reset once at the start of Track.
  struct FrameScratch {
    std::vector<bool> temp_matched;  // matched to a frame-to-frame (temporary) point
    std::vector<Eigen::Vector3d> temp_match_position;
    // The point of an association the pose optimiser rejected (for the geometric check).
    std::vector<bool> dropped;
    std::vector<Eigen::Vector3d> dropped_position;
    void Reset(size_t n);
    void ClearTemporaryMatches();  // track without frame-to-frame points from here on
  };

  // Clears the frame's associations, outlier flags and labels, and the scratch state.
  void PrepareFrame(Frame* frame);
  // Starts a map (the first one, or a new one of the atlas) with `frame` as its root at the origin.
  bool Initialize(Map& map, Frame* frame);
  bool TrackWithMotionModel(const Map& map, Frame* frame);
  bool TrackReferenceKeyFrame(const Map& map, Frame* frame);
  bool TrackLocalMap(Map& map, Frame* frame, int* inliers);
  bool Relocalize(const Map& map, Frame* frame);
  // Whether the frame should become a keyframe; *interrupt: it wanted one while mapping was busy.
  bool NeedNewKeyFrame(const Map& map, const Frame& frame, int inliers,
                       const LocalMappingState& mapping, bool* interrupt) const;
  // Pose optimisation over the frame's matched landmarks and temporary points; marks outliers and
  // drops their associations. Returns the number of inliers.
  int OptimizeFramePose(const Map& map, Frame* frame, bool include_temporary);
  void BuildTemporaryPoints(const Map& map);
  // Labels movers the segmenter missed as kGeometric (after the final pose is known): matched
  // keypoints whose residual is far above the static ones' and confirmed by flagged neighbours,
  // unmatched keypoints next to them at the same depth, and keypoints matching the last frame's
  // movers. Drops their landmark associations and re-optimises the pose if any was an inlier.
  // Returns the number of labelled keypoints.
  int ApplyGeometricCheck(const Map& map, Frame* frame, int* inliers);
  void UpdateLocalMap(const Map& map, const Frame& frame);
  // TrackLocalMap's frustum check: the landmark projects into the frame at its pose (`center`:
  // the camera centre) within the landmark's scale range and viewing angle, and, with
  // check_withheld, not where the frame's keypoints were withheld. *uv: the projection.
  bool InView(const Landmark& lm, const Frame& frame, const Eigen::Vector3d& center,
              bool check_withheld, Eigen::Vector2d* uv) const;
  KeyFrameId CreateLandmarksFromDepth(Map& map, Frame* frame, KeyFrameId kf_id);

  PinholeCamera camera_;
  TrackerOptions options_;
  MoverCheckOptions movers_;
  Rng rng_;
  PoseOptimizerOptions pose_options_;
  TrackingState state_ = TrackingState::kNotInitialized;

  std::optional<Frame> last_frame_;
  std::vector<std::optional<Eigen::Vector3d>> temporary_points_;  // per last-frame keypoint
  std::optional<Rigid3d> velocity_;  // cam_from_world(k) * world_from_cam(k-1)
  double velocity_seconds_ = 0.0;    // stamp(k) - stamp(k-1) of velocity_
  KeyFrameId reference_kf_ = kNoKeyFrame;
  int new_map_id_ = -1;  // >= 0 while Initialize makes the first keyframe of that map
  KeyFrameId last_keyframe_ = kNoKeyFrame;
  int64_t last_keyframe_frame_ = 0;
  bool keyframe_requested_ = false;  // RequestKeyFrame; cleared by the next keyframe
  int64_t last_reloc_frame_ = -1000000;
  Timestamp lost_since_;
  std::vector<KeyFrameId> local_keyframes_;
  std::vector<LandmarkId> local_landmarks_;
  IdStamps local_landmark_set_;  // local_landmarks_ as a set (rebuilt each frame)
  IdStamps matched_set_;         // the current frame's matched landmarks (TrackLocalMap)
  FrameScratch scratch_;
  std::vector<MoverRegion> mover_regions_;  // the geometric check's, of the last frames
};

}  // namespace detslam
