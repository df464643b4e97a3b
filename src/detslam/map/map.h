// The data-only map: keyframes and landmarks owned by id, observations and covisibility by id.
// The Map guards its own invariants: an observation exists in the landmark and in the keyframe's
// slot at the same time, covisibility weights equal the number of shared landmarks.
//
// The Map is also the atlas (ORB-SLAM3's several maps): every keyframe carries a map id, and maps
// never share a landmark or a covisibility edge, so each one has its own world frame. A new map
// starts when tracking is lost (its first keyframe, the map's root, fixes its gauge: never culled,
// no parent, fixed in every optimisation); MergeMapInto moves one map into another's frame once
// place recognition has found and verified their overlap. Place recognition (place_index) spans
// all maps.
#pragma once

#include <Eigen/Core>
#include <map>
#include <memory>
#include <set>
#include <unordered_map>
#include <vector>

#include "detslam/map/frame.h"
#include "detslam/place/keyframe_database.h"

namespace detslam {

struct KeyFrame {
  KeyFrameId id = kNoKeyFrame;
  int map_id = 0;           // the map of the atlas it belongs to (see Map)
  int64_t frame_index = 0;  // input frame it was made from
  Timestamp stamp;
  Rigid3d cam_from_world;
  std::shared_ptr<const FrameFeatures> features;
  std::vector<LandmarkId> landmarks;  // per keypoint
  // Per keypoint (may be empty: all static): kGeometric where the tracker's geometric check found
  // a mover in the frame this keyframe was made from; such keypoints never get new landmarks.
  std::vector<KeypointLabel> labels;
  std::map<KeyFrameId, int> covisibility;  // neighbour -> shared landmarks (>= 1)
  KeyFrameId parent = kNoKeyFrame;         // spanning tree
  std::set<KeyFrameId> children;

  Eigen::Vector3d Center() const { return cam_from_world.Inverse().translation(); }
  size_t size() const { return landmarks.size(); }
};

struct Landmark {
  LandmarkId id = kNoLandmark;
  Eigen::Vector3d position;                          // in the world frame
  std::map<KeyFrameId, size_t> observations;         // keyframe -> keypoint index
  cv::Mat descriptor;                                // 1 x 32, most representative observation
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // mean viewing direction
  double min_distance = 0.0, max_distance = 0.0;     // scale-invariance distance bounds
  KeyFrameId reference_keyframe = kNoKeyFrame;
  KeyFrameId first_keyframe = kNoKeyFrame;
  int visible = 1;  // times it was predicted to be seen in a tracked frame
  int found = 1;    // times it was actually matched

  double FoundRatio() const { return static_cast<double>(found) / std::max(visible, 1); }
  // Predicted pyramid level from the distance to the camera.
  int PredictScale(double distance, const ScaleInfo& scale) const;
};

class Map {
 public:
  explicit Map(ScaleInfo scale) : scale_(std::move(scale)) {}
  // Copies rebuild the id -> element index; moves keep it (map nodes do not move).
  Map(const Map& other);
  Map& operator=(const Map& other);
  Map(Map&&) = default;
  Map& operator=(Map&&) = default;

  // A map rebuilt from stored parts (map files): keyframes and landmarks keep their ids (ascending,
  // below next_keyframe_id / next_landmark_id); keyframe slots are filled from the landmarks'
  // observations, children from the parents; keyframes with a bag-of-words vector enter the place
  // index; each map's root is its lowest keyframe id. Throws InputError(message) when the parts
  // break an invariant (an observation of a missing keyframe or slot, a slot taken twice, a
  // covisibility edge without its reverse or across maps, a landmark seen from two maps, a parent
  // that does not exist or lies in another map, a map root with a parent).
  static Map Restore(ScaleInfo scale, std::vector<KeyFrame> keyframes,
                     std::vector<Landmark> landmarks, KeyFrameId next_keyframe_id,
                     LandmarkId next_landmark_id);
  KeyFrameId next_keyframe_id() const { return next_keyframe_id_; }
  LandmarkId next_landmark_id() const { return next_landmark_id_; }

  // Assigns the id; landmarks vector must be all kNoLandmark. A keyframe whose features have a
  // bag-of-words vector enters the place index. The first keyframe of a map id (kf.map_id) is
  // that map's root.
  KeyFrameId AddKeyFrame(KeyFrame kf);
  LandmarkId AddLandmark(const Eigen::Vector3d& position, KeyFrameId reference);
  // Links landmark `lm` to keypoint `idx` of keyframe `kf` (both must exist, slot must be free).
  void AddObservation(LandmarkId lm, KeyFrameId kf, size_t idx);
  void EraseObservation(LandmarkId lm, KeyFrameId kf);
  void EraseLandmark(LandmarkId lm);
  // Reparents children, removes observations and index entry; a map root is never erased.
  void EraseKeyFrame(KeyFrameId kf);
  // Merges `from` into `into` (all observations move; duplicates in one keyframe are dropped).
  void ReplaceLandmark(LandmarkId from, LandmarkId into);

  // Recomputes covisibility edges of `kf` (and the reciprocal ones) from shared landmarks and
  // sets its parent to the neighbour with most shared points if it has none (a map root never
  // gets one).
  void UpdateConnections(KeyFrameId kf);
  // Recomputes normal, distance bounds and representative descriptor of a landmark.
  void UpdateLandmarkGeometry(LandmarkId lm);
  void UpdateLandmarkDescriptor(LandmarkId lm);

  std::vector<KeyFrameId> BestCovisibles(KeyFrameId kf, size_t n, int min_weight = 0) const;

  bool HasKeyFrame(KeyFrameId id) const { return FindKeyFrame(id) != nullptr; }
  bool HasLandmark(LandmarkId id) const { return FindLandmark(id) != nullptr; }
  KeyFrame& keyframe(KeyFrameId id);
  const KeyFrame& keyframe(KeyFrameId id) const;
  Landmark& landmark(LandmarkId id);
  const Landmark& landmark(LandmarkId id) const;
  const std::map<KeyFrameId, KeyFrame>& keyframes() const { return keyframes_; }
  const std::map<LandmarkId, Landmark>& landmarks() const { return landmarks_; }
  size_t NumKeyFrames() const { return keyframes_.size(); }
  size_t NumLandmarks() const { return landmarks_.size(); }
  const ScaleInfo& scale() const { return scale_; }
  // Bag-of-words inverted index over the keyframes (those made with a vocabulary).
  const KeyFrameDatabase& place_index() const { return place_index_; }
  KeyFrameId first_keyframe() const {
    return keyframes_.empty() ? kNoKeyFrame : keyframes_.begin()->first;
  }

  // --- The atlas: several maps in one container ---
  // An id for a map that has no keyframe yet (ids are never reused).
  int NewMapId() const { return next_map_id_; }
  // Root (first keyframe) of every map that exists, by map id.
  const std::map<int, KeyFrameId>& map_roots() const { return roots_; }
  bool IsMapRoot(KeyFrameId kf) const;
  int MapOf(KeyFrameId kf) const { return keyframe(kf).map_id; }
  // Keyframes of one map, ascending.
  std::vector<KeyFrameId> KeyFramesOfMap(int map_id) const;
  // Their number (ORB-SLAM3's KeyFramesInMap), without building the list.
  size_t NumKeyFramesOfMap(int map_id) const;
  // Moves map `from` into map `into`: every keyframe and landmark of `from` is transformed by
  // `into_from_from` (world_into_from_world_from) and relabelled, its spanning tree is re-rooted
  // at `seam` (a keyframe of `from`) and hung below `into_seam` (a keyframe of `into`). Returns
  // the poses (cam_from_world) of the moved keyframes before the move.
  std::map<KeyFrameId, Rigid3d> MergeMapInto(int from, int into, const Rigid3d& into_from_from,
                                             KeyFrameId seam, KeyFrameId into_seam);
  // Number of landmarks of `kf` observed by at least `min_obs` keyframes.
  int TrackedLandmarks(KeyFrameId kf, int min_obs) const;

 private:
  // O(1) lookups by id (ids are dense: assigned in order from 0); null where erased. The ordered
  // maps own the elements and give the deterministic iteration order; a lookup in them costs a
  // root-to-leaf walk, which grows with the map (2 million landmarks: about 21 cache misses).
  KeyFrame* FindKeyFrame(KeyFrameId id) const {
    return id >= 0 && static_cast<size_t>(id) < keyframe_at_.size()
               ? keyframe_at_[static_cast<size_t>(id)]
               : nullptr;
  }
  Landmark* FindLandmark(LandmarkId id) const {
    return id >= 0 && static_cast<size_t>(id) < landmark_at_.size()
               ? landmark_at_[static_cast<size_t>(id)]
               : nullptr;
  }
  void RebuildIndex();

  ScaleInfo scale_;
  std::map<KeyFrameId, KeyFrame> keyframes_;  // ordered: deterministic iteration
  std::map<LandmarkId, Landmark> landmarks_;
  std::vector<KeyFrame*> keyframe_at_;  // id -> element of keyframes_ (null: erased)
  std::vector<Landmark*> landmark_at_;  // id -> element of landmarks_ (null: erased)
  KeyFrameDatabase place_index_;
  std::map<int, KeyFrameId> roots_;  // map id -> its first keyframe
  int next_map_id_ = 0;
  KeyFrameId next_keyframe_id_ = 0;
  LandmarkId next_landmark_id_ = 0;
};

}  // namespace detslam
