// Loop closing for RGB-D: after local mapping of a keyframe, look for an older keyframe of the
// same place that is not in its covisibility neighbourhood, verify the loop geometrically (3-D to
// 3-D rigid RANSAC on descriptor matches with the keyframe's depth, then pose-only optimisation
// with more matches by projection), fuse the duplicated landmarks, and distribute the correction
// over the map by a pose-graph optimisation (spanning tree, strong covisibility edges, loop edges;
// ORB-SLAM's essential graph), moving every landmark with its reference keyframe. The bundle
// adjustment of the whole map that follows (global_ba_iterations) is the caller's step, outside
// the map lock (mapping/map_bundle.h GlobalBundleAdjustment).
//
// Several maps (Map is the atlas): a candidate in another map is a merge (Merge). The position
// gate and the recent-keyframe exclusion apply within the keyframe's own map only (another map's
// positions are in another frame); merges need a vocabulary.
//
// Candidates: with a vocabulary (keyframes carry bag-of-words vectors), by appearance among the
// keyframes that are neither covisible with the new one nor among its `min_keyframe_gap` newest
// (place_candidates.h), the best `appearance_candidates` groups; `candidate_radius_m` > 0 adds a
// position gate (candidate centre within that distance of the new keyframe's). A verified
// candidate is accepted once `consistent_detections` keyframes agree with it (ORB-SLAM3's
// covisibility/temporal check): the keyframe itself, its best covisibles into which the loop
// side's landmarks project with at least `confirm_min_matches` matches at the corrected pose, and
// the next keyframes, verified again from the predicted correction; a pending loop is dropped after
// `max_pending_misses` next keyframes in a row that do not confirm it. Without a vocabulary: the keyframes within
// `candidate_radius_m`, nearest first (needs a radius > 0), accepted on verification alone.
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "detslam/core/camera.h"
#include "detslam/core/rng.h"
#include "detslam/map/map.h"
#include "detslam/map/place_candidates.h"
#include "detslam/map/projection_search.h"
#include "detslam/mapping/map_bundle.h"
#include "detslam/optim/pose_graph.h"

namespace detslam {

struct LoopClosingOptions {
  bool enabled = true;
  int min_keyframe_gap = 20;        // candidates at least this many keyframe ids older
  double candidate_radius_m = 0.0;  // > 0: candidate keyframe centres within this distance
  int consistent_detections = 3;    // keyframes that must agree on a loop found by appearance
  int appearance_candidates = 3;    // bag-of-words groups verified per keyframe (best first)
  int max_candidates = 8;           // by position: examined per keyframe (nearest first)
  int confirm_min_matches = 30;     // projection matches for a covisible keyframe to agree
  int max_pending_misses = 2;       // next keyframes in a row that fail before a pending loop goes
  // A verified loop that would move its keyframe less than both of these is a revisit: landmarks
  // fused, no pose correction, not counted as a loop closed.
  double revisit_max_correction_m = 0.01;
  double revisit_max_correction_deg = 1.0;
  int candidate_window = 10;  // best covisibles of a candidate matched along with it
  DescriptorSearch window_search = DescriptorSearch::kBruteForce;
  int min_matches = 40;             // descriptor matches with depth to try RANSAC
  double ransac_inlier_m = 0.05;    // 3-D inlier distance (scaled by depth / 2 m, at least this)
  int min_ransac_inliers = 30;
  int min_verified_inliers = 80;   // pose-only inliers after the projection search
  int essential_min_weight = 100;  // covisibility edges kept in the pose graph
  // A merge is welded (ORB-SLAM3's MergeLocal): after the fusion, a bundle adjustment of the
  // moved map's side of the seam (its seam keyframe and best covisibles of the same map, up to this
  // many) against the kept map's side (its seam keyframe and best covisibles, as many, and the
  // other keyframes that observe the window's points most) held fixed; then the pose graph over the
  // moved map only, with that window fixed. 0: no welding window (the pose graph over the merged
  // map, as for a loop).
  int merge_weld_keyframes = 15;
  int merge_weld_iterations = 10;  // its Levenberg-Marquardt iterations
  int global_ba_iterations =
      10;  // bundle adjustment of the whole map after the pose graph (0: none; run by the caller)
  uint64_t seed = 7;  // RANSAC
  bool Check(std::string* error) const;
};

struct LoopClosingResult {
  bool closed = false;
  bool revisit = false;  // verified, but the map already agreed: landmarks fused, nothing moved
  KeyFrameId keyframe = kNoKeyFrame;   // the keyframe that closed the loop
  KeyFrameId candidate = kNoKeyFrame;  // the older keyframe of the same place
  int inliers = 0;                     // verified pose-only inliers
  int agreeing = 0;  // keyframes that agreed on it (appearance; 1 for a loop found by position)
  int fused = 0;                       // landmarks merged
  double correction_m = 0;             // how far the keyframe moved
  // The relative pose the loop asserts: the keyframe's verified pose in the candidate's camera
  // frame (candidate's cam_from_world before the correction times the verified world_from_cam),
  // what a benchmark compares with ground truth to tell a true loop from a false one.
  Rigid3d candidate_from_keyframe;
  // The candidate lay in another map of the atlas: the two maps were merged (map `merged_from`
  // moved into map `merged_into`'s frame; the one whose root is older keeps its frame), then
  // welded (fusion, a bundle adjustment of the moved map's side of the seam, the pose graph over
  // the moved map with that window fixed). `closed` is set too.
  bool merged = false;
  int merged_from = -1, merged_into = -1;
  int welded_keyframes = 0;  // keyframes the seam's bundle adjustment optimised
  // Keyframe poses before the correction (cam_from_world), for the tracker and the trajectory.
  std::map<KeyFrameId, Rigid3d> old_poses;
};

// How far loop candidates got (counted over a run): the stage that rejected them shows whether a
// look-alike place was turned down by the geometry or never proposed.
struct LoopDetectionStats {
  int candidates = 0;       // candidates examined (after appearance or position selection)
  int enough_matches = 0;   // with at least min_matches descriptor matches with depth
  int rigid_ransac = 0;     // passed 3-D rigid RANSAC (min_ransac_inliers)
  int verified = 0;         // passed pose-only verification (min_verified_inliers)
  int pending_confirmed = 0;  // next keyframes that confirmed a pending loop
  int pending_dropped = 0;    // pending loops given up
  int revisits = 0;  // verified and agreed on, but within revisit_max_correction: not corrected
};

class LoopCloser {
 public:
  LoopCloser(const PinholeCamera& camera, LoopClosingOptions options);

  // Runs one step with the map: `run_step(step)` calls step(map), e.g. under the map store's
  // write access.
  using MapStep = std::function<void(Map&)>;
  using StepRunner = std::function<void(const MapStep&)>;
  // Called in the last step of Process, under the same access as the correction (e.g. to move the
  // tracker's state with the map), whether a loop was closed or not.
  using FinishFn = std::function<void(Map&, const LoopClosingResult&)>;
  // A correction moves the map in steps, with the solves between them done without the map
  // (tracking goes on). The first step moves part of the map at once (a loop: the keyframe's
  // neighbourhood to the loop's frame; a merge: the moved map into the kept map's frame) and calls
  // this under its access with those keyframes' poses before it (e.g. to move the tracker's last
  // frame, and to mark a global BA started earlier as stale); a welded merge's seam bundle
  // adjustment and then the pose graph are solved without the map, each applied in a step of its
  // own, and the last step moves the landmarks and calls `finish`.
  using MovedFn = std::function<void(Map&, const std::map<KeyFrameId, Rigid3d>& old_poses)>;

  // Looks for and closes a loop at keyframe `kf` of `map`. Deterministic.
  LoopClosingResult Process(Map& map, KeyFrameId kf);
  // The same in steps, each run by `run_step` (so a lock can be released between them and
  // tracking does not wait for the whole search): the candidate search, each candidate's
  // verification, then the closing (fusion, pose graph) with `finish`, in two or three steps with
  // the solves between them (see MovedFn). Between steps tracking may add keyframes and points,
  // and until `before_closing` a local-mapping thread may also erase and move them: every step
  // checks again that the keyframes it uses exist, and results carried across steps refer to
  // landmarks by id and are checked again. With nothing else changing the map between steps, the
  // result equals Process(map, kf).
  // `before_closing` (may be null) is called, outside any step, just before the step that closes
  // a loop or merges maps, i.e. only when one will be: e.g. to hold a local-mapping thread that
  // erases keyframes and runs bundle adjustments, until Process returns.
  LoopClosingResult Process(const StepRunner& run_step, KeyFrameId kf, const FinishFn& finish,
                            const MovedFn& moved = nullptr,
                            const std::function<void()>& before_closing = nullptr);

  int loops_closed() const { return loops_closed_; }  // merges not included
  int maps_merged() const { return maps_merged_; }
  const LoopDetectionStats& stats() const { return stats_; }
  // A loop verified but not yet agreed on by enough keyframes: the next keyframes decide.
  bool has_pending() const { return pending_.has_value(); }

 private:
  struct Verified {
    KeyFrameId candidate = kNoKeyFrame;
    KeyFrameId keyframe = kNoKeyFrame;
    Rigid3d cam_from_world;           // corrected pose of the keyframe
    Rigid3d correction;               // world_new_from_world_old that the loop implies
    std::vector<LandmarkId> matched;  // per keypoint of the current keyframe
    // Landmarks of the candidate's neighbourhood, to fuse into the current keyframe's.
    std::vector<LandmarkId> loop_landmarks;
    int inliers = 0;
    int coincidences = 0;  // keyframes that agree (appearance only)
    int misses = 0;        // next keyframes in a row that did not
  };
  // A correction in steps, each under the caller's access, with the two solves between them
  // without the map (tracking goes on): BeginCorrection (fusion; a loop's neighbourhood moved
  // rigidly to the loop's frame; for a welded merge the seam's bundle built), the weld solved,
  // BuildEssentialGraph (the weld applied, the pose graph built), the pose graph solved,
  // ApplyEssentialGraph (the poses set, keyframes made meanwhile moved with their parents, the
  // landmarks moved with their reference keyframes).
  struct Correction {
    Verified loop;
    bool correct_poses = true;  // false: a revisit (fusion only)
    bool merge = false;
    int merged_from = -1, merged_into = -1;
    std::set<KeyFrameId> moved;                  // a merge: the moved map's keyframes
    std::map<KeyFrameId, Rigid3d> before_merge;  // and their poses before the move
    // The first step's move (a merge: the moved map; a loop: its group): the poses before it (for
    // MovedFn) and after it; tracker_moved: MovedFn was called.
    std::map<KeyFrameId, Rigid3d> jumped_from, jumped_to;
    bool tracker_moved = false;
    std::map<KeyFrameId, Rigid3d> old_pose;  // every keyframe's pose before the correction
    std::map<LandmarkId, Eigen::Vector3d> old_position;
    // The keyframe pose each landmark's old_position is relative to (old_pose, except where a
    // step before the pose graph already moved the keyframe with its landmarks).
    std::map<KeyFrameId, Rigid3d> moved_from;
    std::vector<KeyFrameId> group;  // the keyframe and its covisibles, moved rigidly with it
    std::map<KeyFrameId, std::set<KeyFrameId>> connected_before;
    std::map<KeyFrameId, Rigid3d> initial;  // the pose graph's starting poses
    std::optional<MapBundle> weld;          // the seam's bundle, to solve
    std::optional<PoseGraphProblem> graph;  // the essential graph, to solve
  };
  bool WithinRadius(const Map& map, KeyFrameId kf, KeyFrameId other) const;
  std::vector<KeyFrameId> CandidatesByPosition(const Map& map, KeyFrameId kf) const;
  std::vector<KeyFrameId> CandidatesByAppearance(const Map& map, KeyFrameId kf) const;
  // Descriptor matching against the candidate's window, rigid RANSAC, then Refine.
  bool Verify(const Map& map, KeyFrameId kf, KeyFrameId candidate, Verified* out);
  // From `pose` and the associations in `assoc` (per keypoint of kf), more matches by projecting
  // out->loop_landmarks, pose-only optimisation; fills `out` when enough inliers remain.
  bool Refine(const Map& map, KeyFrameId kf, Rigid3d pose, std::vector<LandmarkId> assoc,
              Verified* out) const;
  // Number of loop-side landmarks matched by projection into keyframe `kf` at its pose moved by
  // `correction`.
  int ProjectionMatches(const Map& map, KeyFrameId kf, const Rigid3d& correction,
                        const std::vector<LandmarkId>& landmarks) const;
  // Appearance: keyframes agreeing with a loop just verified at `loop.keyframe` (it and its best
  // covisibles), up to consistent_detections.
  int CountCoincidences(const Map& map, const Verified& loop) const;
  // Appearance: a pending loop checked against the new keyframe `kf`; true if it agrees (then the
  // pending loop is re-verified at kf).
  bool ConfirmPending(const Map& map, KeyFrameId kf);
  // Closes the verified loop (or merges the maps) up to what is solved without the map: returns
  // true when c->weld or c->graph is left to solve (then BuildEssentialGraph after a weld,
  // ApplyEssentialGraph and Conclude); false for a revisit.
  bool Close(Map& map, KeyFrameId kf, const Verified& loop, LoopClosingResult* result,
             Correction* c);
  // A verified candidate in another map: moves the map whose root is newer into the other's frame
  // (Map::MergeMapInto), then corrects (welds) the seam; returns as Close.
  bool Merge(Map& map, KeyFrameId kf, Verified loop, LoopClosingResult* result, Correction* c);
  // Fuses the loop side's landmarks into kf's neighbourhood. With c->correct_poses: a loop moves
  // that neighbourhood (c->group) and the landmarks it made to the loop's frame at once (ORB-SLAM's
  // CorrectLoop), so tracking meets one consistent place until the pose graph is applied; a merge
  // with merge_weld_keyframes > 0 builds the bundle of the moved map's side of the seam against
  // the kept map's (c->weld; none when it would be empty); else the pose graph is built.
  void BeginCorrection(Map& map, KeyFrameId kf, Correction* c, LoopClosingResult* result);
  // Applies the solved weld (`weld`: its summary, null when none was built), then builds the
  // essential graph (c->graph) over kf's map: spanning tree, strong covisibility, the new loop
  // connections; a merge's weld window and the kept map fixed. Keyframes and landmarks made
  // since BeginCorrection are taken as they are.
  void BuildEssentialGraph(Map& map, KeyFrameId kf, Correction* c, const BundleSummary* weld,
                           LoopClosingResult* result);
  // Sets the solved graph's poses; keyframes made since it was built move with their parent (or
  // best covisible) and every landmark with its reference keyframe.
  void ApplyEssentialGraph(Map& map, KeyFrameId kf, Correction* c, const PoseGraphSummary& s,
                           LoopClosingResult* result);
  // The correction's bookkeeping once applied: counters, log, result->old_poses.
  void Conclude(Correction* c, KeyFrameId kf, LoopClosingResult* result);

  PinholeCamera camera_;
  LoopClosingOptions options_;
  Rng rng_;
  std::optional<Verified> pending_;  // appearance: verified but not yet agreed on
  KeyFrameId last_loop_kf_ = kNoKeyFrame;
  int loops_closed_ = 0;
  int maps_merged_ = 0;
  LoopDetectionStats stats_;
};

}  // namespace detslam
