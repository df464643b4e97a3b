// Local mapping for RGB-D keyframes (ORB-SLAM3 rules): landmark culling, triangulation of new
// landmarks with neighbour keyframes, fusion of duplicate landmarks with neighbour keyframes,
// local bundle adjustment (Ceres) over the keyframe's covisibility neighbourhood, and
// redundant-keyframe culling.
#pragma once

#include <atomic>
#include <deque>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "detslam/map/map.h"
#include "detslam/map/map_store.h"

namespace detslam {

struct LocalMapperOptions {
  bool local_ba = true;           // run local bundle adjustment after each keyframe
  int ba_iterations = 10;         // Levenberg-Marquardt iterations
  int ba_dense_schur_max_poses = 64;  // BundleOptions::dense_schur_max_poses (0: Ceres)
  int max_local_keyframes = 20;   // optimised keyframes: current + best covisibles
  int max_fixed_keyframes = 40;   // keyframes observing local points, kept fixed
  bool fuse = true;               // SearchInNeighbors
  int fuse_neighbours = 10;       // first-order neighbours to fuse with
  bool cull_keyframes = true;     // KeyFrameCulling
  double redundancy = 0.9;        // cull if this fraction of points is seen by >= 3 others
  double min_found_ratio = 0.25;  // landmark culling: found / visible
  // CreateNewMapPoints: keypoints without a landmark and without close depth (none, or beyond
  // ThDepth) are matched with those of the best covisible keyframes and triangulated.
  bool triangulate = true;
  int triangulation_neighbours = 10;  // best covisible keyframes to triangulate with (RGB-D: 10)
  bool Check(std::string* error) const;
};

// A keyframe that culling removed, with its pose relative to its parent at that time, so frames
// that referred to it can still be placed.
struct ErasedKeyFrame {
  KeyFrameId id = kNoKeyFrame;
  KeyFrameId parent = kNoKeyFrame;
  Rigid3d cam_from_parent;
};

struct LocalMappingSummary {
  int fused = 0;
  int triangulated = 0;
  int culled_landmarks = 0;
  int ba_outliers = 0;
  double ba_ms = 0.0;
  bool skipped_for_waiting = false;  // keyframes waited: no fusion, BA or keyframe culling
  std::vector<ErasedKeyFrame> erased_keyframes;
};

// How a threaded run lets local mapping keep up with the tracker (ORB-SLAM3's LocalMapping):
// while more keyframes wait, a keyframe gets no fusion, bundle adjustment or keyframe culling
// (the last of a burst gets them, over the neighbourhood of all), and a bundle adjustment stops
// after its current iteration when the tracker asks (InterruptBA). Sequential runs leave both off.
struct LocalMappingControl {
  std::function<bool()> keyframes_waiting;  // null: never
  const std::atomic<bool>* abort_ba = nullptr;
};

class LocalMapper {
 public:
  LocalMapper(const PinholeCamera& camera, LocalMapperOptions options);

  // Processes a keyframe just inserted by the tracker. Deterministic (with the default control).
  // Every step holds the store's write access except the triangulation's descriptor matching (one
  // neighbour at a time) and the bundle-adjustment solve (on a snapshot,
  // MapStore::ComputeOutsideLock), which run while the tracker may use the map; landmark fusion
  // takes the access once per neighbour keyframe.
  LocalMappingSummary ProcessKeyFrame(KeyFrameId kf, MapStore* store,
                                      const LocalMappingControl& control = {});

 private:
  void CullLandmarks(Map& map, KeyFrameId current, LocalMappingSummary* summary);
  void TriangulateNewLandmarks(MapStore* store, KeyFrameId current,
                               LocalMappingSummary* summary);  // triangulate.cc
  void FuseWithNeighbours(MapStore* store, KeyFrameId current, LocalMappingSummary* summary);
  void LocalBundleAdjustment(MapStore* store, KeyFrameId current,
                             const std::atomic<bool>* abort_ba, LocalMappingSummary* summary);
  void CullKeyFrames(Map& map, KeyFrameId current, LocalMappingSummary* summary);

  PinholeCamera camera_;
  LocalMapperOptions options_;
  std::deque<LandmarkId> recent_landmarks_;
};

}  // namespace detslam
