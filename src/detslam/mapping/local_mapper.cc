#include "detslam/mapping/local_mapper.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "detslam/core/check.h"
#include "detslam/features/matcher.h"
#include "detslam/map/projection_search.h"
#include "detslam/mapping/landmark_fusion.h"
#include "detslam/mapping/map_bundle.h"
#include "detslam/optim/bundle_adjustment.h"

namespace detslam {

bool LocalMapperOptions::Check(std::string* error) const {
  std::ostringstream os;
  if (ba_iterations < 1) os << "ba_iterations must be >= 1; ";
  if (ba_dense_schur_max_poses < 0) os << "ba_dense_schur_max_poses must be >= 0; ";
  if (max_local_keyframes < 1) os << "max_local_keyframes must be >= 1; ";
  if (triangulation_neighbours < 1) os << "triangulation_neighbours must be >= 1; ";
  if (!(redundancy > 0 && redundancy <= 1)) os << "redundancy must be in (0, 1]; ";
  if (error) *error = os.str();
  return os.str().empty();
}

LocalMapper::LocalMapper(const PinholeCamera& camera, LocalMapperOptions options)
    : camera_(camera), options_(options) {
  std::string error;
  DETSLAM_CHECK_MSG(options_.Check(&error), error);
}

LocalMappingSummary LocalMapper::ProcessKeyFrame(KeyFrameId current, MapStore* store,
                                                 const LocalMappingControl& control) {
  const auto waiting = [&control] {
    return control.keyframes_waiting && control.keyframes_waiting();
  };
  LocalMappingSummary summary;
  {
    const MapStore::WriteAccess access = store->Write();
    Map& map = *access;
    KeyFrame& kf = map.keyframe(current);
    for (LandmarkId lm : kf.landmarks) {
      if (lm == kNoLandmark) continue;
      Landmark& l = map.landmark(lm);
      if (l.first_keyframe == current) {
        recent_landmarks_.push_back(lm);
      } else {
        map.UpdateLandmarkGeometry(lm);
        map.UpdateLandmarkDescriptor(lm);
      }
    }
    map.UpdateConnections(current);
    CullLandmarks(map, current, &summary);
  }
  if (options_.triangulate) TriangulateNewLandmarks(store, current, &summary);
  // With more keyframes waiting, fusion and then BA and culling are left to a later keyframe.
  const bool fuse = !waiting();
  if (fuse && options_.fuse) FuseWithNeighbours(store, current, &summary);
  const bool bundle_adjust = options_.local_ba && store->Read()->NumKeyFrames() > 2;
  const bool skip_ba = waiting();
  summary.skipped_for_waiting = !fuse || skip_ba;
  if (skip_ba) return summary;
  if (bundle_adjust) LocalBundleAdjustment(store, current, control.abort_ba, &summary);
  if (options_.cull_keyframes) CullKeyFrames(*store->Write(), current, &summary);
  return summary;
}

void LocalMapper::CullLandmarks(Map& map, KeyFrameId current, LocalMappingSummary* summary) {
  std::deque<LandmarkId> keep;
  for (LandmarkId id : recent_landmarks_) {
    if (!map.HasLandmark(id)) continue;
    const Landmark& lm = map.landmark(id);
    const KeyFrameId age = current - lm.first_keyframe;
    if (lm.FoundRatio() < options_.min_found_ratio || (age >= 2 && lm.observations.size() < 2)) {
      map.EraseLandmark(id);
      ++summary->culled_landmarks;
    } else if (age < 3) {
      keep.push_back(id);
    }
  }
  recent_landmarks_ = std::move(keep);
}

void LocalMapper::FuseWithNeighbours(MapStore* store, KeyFrameId current,
                                     LocalMappingSummary* summary) {
  // Each step under its own write access, one neighbour at a time: the tracker may take the map
  // between them (a whole fusion under one access held tracking up for tens of milliseconds at
  // camera rate). The steps and their order are those of one access; a keyframe removed meanwhile
  // is skipped.
  std::vector<KeyFrameId> targets;
  {
    const MapStore::ReadAccess map = store->Read();
    if (!map->HasKeyFrame(current)) return;
    targets = map->BestCovisibles(current, static_cast<size_t>(options_.fuse_neighbours));
    std::set<KeyFrameId> target_set(targets.begin(), targets.end());
    const size_t first_order = targets.size();
    for (size_t k = 0; k < first_order; ++k) {
      for (KeyFrameId n : map->BestCovisibles(targets[k], 5)) {
        if (n != current && target_set.insert(n).second) targets.push_back(n);
      }
    }
  }
  ProjectionSearchOptions opt;
  opt.window = 3.0;
  opt.ratio = 1.0;
  opt.max_distance = kThLow;
  auto fuse_into = [&](Map& map, KeyFrameId into, const std::vector<LandmarkId>& sources) {
    summary->fused +=
        FuseLandmarksInto(camera_, map, into, sources, map.keyframe(into).cam_from_world, opt,
                          FuseWinner::kMoreObserved);
  };
  for (KeyFrameId t : targets) {
    const MapStore::WriteAccess access = store->Write();
    Map& map = *access;
    if (!map.HasKeyFrame(current)) return;
    if (!map.HasKeyFrame(t)) continue;
    std::vector<LandmarkId> mine;
    for (LandmarkId id : map.keyframe(current).landmarks) {
      if (id != kNoLandmark) mine.push_back(id);
    }
    fuse_into(map, t, mine);
  }
  const MapStore::WriteAccess access = store->Write();
  Map& map = *access;
  if (!map.HasKeyFrame(current)) return;
  std::vector<LandmarkId> theirs;
  std::set<LandmarkId> seen;
  for (KeyFrameId t : targets) {
    if (!map.HasKeyFrame(t)) continue;
    for (LandmarkId id : map.keyframe(t).landmarks) {
      if (id != kNoLandmark && seen.insert(id).second) theirs.push_back(id);
    }
  }
  fuse_into(map, current, theirs);
  for (LandmarkId id : map.keyframe(current).landmarks) {
    if (id == kNoLandmark) continue;
    map.UpdateLandmarkDescriptor(id);
    map.UpdateLandmarkGeometry(id);
  }
  map.UpdateConnections(current);
}

void LocalMapper::LocalBundleAdjustment(MapStore* store, KeyFrameId current,
                                        const std::atomic<bool>* abort_ba,
                                        LocalMappingSummary* summary) {
  const auto t0 = std::chrono::steady_clock::now();
  // Snapshot: the current keyframe and its best covisibles are optimised; the keyframes that
  // observe their points most (up to max_fixed_keyframes) are held fixed.
  auto snapshot = [&](const Map& map) -> std::optional<MapBundle> {
    std::vector<KeyFrameId> local = {current};
    for (KeyFrameId k :
         map.BestCovisibles(current, static_cast<size_t>(options_.max_local_keyframes - 1)))
      local.push_back(k);
    MapBundle bundle = BuildWindowBundle(map, local, options_.max_fixed_keyframes);
    if (bundle.problem.poses.empty())
      return std::nullopt;  // no gauge: ORB-SLAM skips local BA then
    return bundle;
  };
  auto solve = [&](MapBundle& bundle) {
    BundleOptions bo;
    bo.max_iterations = options_.ba_iterations;
    bo.dense_schur_max_poses = options_.ba_dense_schur_max_poses;
    return SolveBundle(camera_, &bundle.problem, bo, abort_ba);
  };
  auto apply = [&](Map& map, const MapBundle& bundle, const BundleSummary& s) {
    if (!s.usable) return;
    summary->ba_outliers += ApplyMapBundle(bundle, s, &map);
    summary->ba_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  };
  store->ComputeOutsideLock(snapshot, solve, apply);
}

void LocalMapper::CullKeyFrames(Map& map, KeyFrameId current, LocalMappingSummary* summary) {
  for (KeyFrameId k : map.BestCovisibles(current, 1000)) {
    if (map.IsMapRoot(k) || k == current || !map.HasKeyFrame(k)) continue;
    const KeyFrame& kf = map.keyframe(k);
    int total = 0, redundant = 0;
    for (size_t i = 0; i < kf.size(); ++i) {
      const LandmarkId id = kf.landmarks[i];
      if (id == kNoLandmark) continue;
      const float d = kf.features->depth[i];
      if (d <= 0 || d > camera_.CloseDepthThreshold()) continue;
      ++total;
      const Landmark& lm = map.landmark(id);
      if (lm.observations.size() <= 3) continue;
      const int level = kf.features->keypoints[i].octave;
      int seen = 0;
      for (const auto& [other, idx] : lm.observations) {
        if (other == k) continue;
        if (map.keyframe(other).features->keypoints[idx].octave <= level + 1 && ++seen >= 3) break;
      }
      if (seen >= 3) ++redundant;
    }
    if (total > 0 && redundant > options_.redundancy * total) {
      ErasedKeyFrame e;
      e.id = k;
      e.parent = kf.parent;
      if (map.HasKeyFrame(kf.parent))
        e.cam_from_parent = kf.cam_from_world * map.keyframe(kf.parent).cam_from_world.Inverse();
      map.EraseKeyFrame(k);
      summary->erased_keyframes.push_back(e);
    }
  }
}

}  // namespace detslam
