#include "detslam/mapping/map_bundle.h"

#include <algorithm>
#include <map>
#include <optional>
#include <set>
#include <utility>

namespace detslam {

MapBundle BuildMapBundle(const Map& map, const std::vector<KeyFrameId>& free,
                         const std::vector<KeyFrameId>& fixed) {
  MapBundle b;
  std::map<KeyFrameId, size_t> pose_index;
  auto add_pose = [&](KeyFrameId k, bool is_fixed) {
    if (pose_index.count(k)) return;
    pose_index[k] = b.problem.poses.size();
    b.problem.poses.push_back({k, map.keyframe(k).cam_from_world, is_fixed || map.IsMapRoot(k)});
  };
  for (KeyFrameId k : free) add_pose(k, false);
  for (KeyFrameId k : fixed) add_pose(k, true);
  bool any_fixed = false;
  for (const auto& p : b.problem.poses) any_fixed |= p.fixed;
  if (!any_fixed) return MapBundle();
  std::set<LandmarkId> seen;
  for (KeyFrameId k : free) {
    for (LandmarkId id : map.keyframe(k).landmarks) {
      if (id == kNoLandmark || !seen.insert(id).second) continue;
      const Landmark& lm = map.landmark(id);
      const size_t pi = b.problem.points.size();
      b.problem.points.push_back({lm.id, lm.position, false});
      for (const auto& [kf, idx] : lm.observations) {
        auto it = pose_index.find(kf);
        if (it == pose_index.end()) continue;
        const FrameFeatures& f = *map.keyframe(kf).features;
        BundleProblem::Observation o;
        o.pose_index = it->second;
        o.point_index = pi;
        o.uv = f.undist[idx];
        o.u_right = f.u_right[idx];
        o.inv_sigma2 = map.scale().inv_level_sigma2[static_cast<size_t>(f.keypoints[idx].octave)];
        b.problem.observations.push_back(o);
        b.observation_ref.emplace_back(lm.id, kf);
      }
    }
  }
  return b;
}

MapBundle BuildWindowBundle(const Map& map, const std::vector<KeyFrameId>& window, int max_fixed,
                            const std::vector<KeyFrameId>& held) {
  std::set<KeyFrameId> not_counted(window.begin(), window.end());  // the window and `held`
  not_counted.insert(held.begin(), held.end());
  std::vector<LandmarkId> points;
  std::set<LandmarkId> point_set;
  for (KeyFrameId k : window) {
    for (LandmarkId id : map.keyframe(k).landmarks) {
      if (id != kNoLandmark && point_set.insert(id).second) points.push_back(id);
    }
  }
  std::map<KeyFrameId, int> fixed_counts;
  for (LandmarkId id : points) {
    for (const auto& [kf, idx] : map.landmark(id).observations) {
      (void)idx;
      if (!not_counted.count(kf)) ++fixed_counts[kf];
    }
  }
  std::vector<std::pair<int, KeyFrameId>> fixed_sorted;
  for (const auto& [kf, n] : fixed_counts) fixed_sorted.emplace_back(-n, kf);
  std::sort(fixed_sorted.begin(), fixed_sorted.end());
  std::vector<KeyFrameId> fixed;
  for (KeyFrameId k : held)
    if (std::find(window.begin(), window.end(), k) == window.end()) fixed.push_back(k);
  for (size_t i = 0; i < fixed_sorted.size() && static_cast<int>(i) < max_fixed; ++i)
    fixed.push_back(fixed_sorted[i].second);
  return BuildMapBundle(map, window, fixed);
}

int ApplyMapBundle(const MapBundle& bundle, const BundleSummary& summary, Map* map) {
  int erased = 0;
  for (size_t k = 0; k < bundle.problem.observations.size(); ++k) {
    const auto& [lm, kf] = bundle.observation_ref[k];
    if (summary.outlier[k] && map->HasLandmark(lm) && map->landmark(lm).observations.count(kf)) {
      map->EraseObservation(lm, kf);
      ++erased;
    }
  }
  for (const auto& p : bundle.problem.poses) {
    if (!p.fixed && map->HasKeyFrame(p.id)) map->keyframe(p.id).cam_from_world = p.cam_from_world;
  }
  for (const auto& p : bundle.problem.points) {
    if (!map->HasLandmark(p.id)) continue;
    map->landmark(p.id).position = p.p_world;
    map->UpdateLandmarkGeometry(p.id);
  }
  return erased;
}

void MoveWithParents(const std::set<KeyFrameId>& solved,
                     const std::map<KeyFrameId, Rigid3d>& before, Map* map) {
  std::vector<KeyFrameId> queue;
  for (const auto& [map_id, root] : map->map_roots()) {  // every map's tree, from its root
    (void)map_id;
    queue.push_back(root);
  }
  std::set<KeyFrameId> visited(queue.begin(), queue.end());
  for (size_t q = 0; q < queue.size(); ++q) {
    const KeyFrameId parent = queue[q];
    const std::set<KeyFrameId> children = map->keyframe(parent).children;
    for (KeyFrameId child : children) {
      if (!map->HasKeyFrame(child) || !visited.insert(child).second) continue;
      queue.push_back(child);
      if (solved.count(child)) continue;
      const Rigid3d child_from_parent = before.at(child) * before.at(parent).Inverse();
      map->keyframe(child).cam_from_world =
          child_from_parent * map->keyframe(parent).cam_from_world;
    }
  }
}

KeyFrameId LandmarkAnchor(const Map& map, LandmarkId id, const std::map<KeyFrameId, Rigid3d>& poses) {
  const Landmark& lm = map.landmark(id);
  KeyFrameId ref = lm.reference_keyframe;
  if (!map.HasKeyFrame(ref) || !poses.count(ref)) {
    if (lm.observations.empty()) return kNoKeyFrame;
    ref = lm.observations.begin()->first;
  }
  return map.HasKeyFrame(ref) && poses.count(ref) ? ref : kNoKeyFrame;
}

void PropagateBundleCorrection(const MapBundle& bundle, const std::map<KeyFrameId, Rigid3d>& before,
                               Map* map) {
  std::set<KeyFrameId> solved;
  for (const auto& p : bundle.problem.poses) solved.insert(p.id);
  MoveWithParents(solved, before, map);
  std::set<LandmarkId> held;
  for (const auto& p : bundle.problem.points) held.insert(p.id);
  std::vector<std::pair<LandmarkId, KeyFrameId>> moved;
  for (const auto& [id, lm] : map->landmarks()) {
    (void)lm;
    if (held.count(id)) continue;
    const KeyFrameId anchor = LandmarkAnchor(*map, id, before);
    if (anchor != kNoKeyFrame) moved.emplace_back(id, anchor);
  }
  for (const auto& [id, anchor] : moved) {
    Landmark& lm = map->landmark(id);
    lm.position = map->keyframe(anchor).cam_from_world.Inverse() * (before.at(anchor) * lm.position);
    map->UpdateLandmarkGeometry(id);
  }
}

BundleSummary GlobalBundleAdjustment(const PinholeCamera& camera, int iterations, MapStore* store,
                                     const MapUpdatedFn& applied,
                                     const std::function<bool(const Map&)>& still_valid,
                                     const std::atomic<bool>* abort_flag) {
  BundleSummary summary;
  auto snapshot = [](const Map& map) -> std::optional<MapBundle> {
    std::vector<KeyFrameId> all;
    for (const auto& [id, kf] : map.keyframes()) {
      (void)kf;
      all.push_back(id);
    }
    MapBundle b = BuildMapBundle(map, all, {});
    if (b.problem.poses.empty() || b.problem.observations.empty()) return std::nullopt;
    return b;
  };
  auto solve = [&](MapBundle& b) {
    BundleOptions bo;
    bo.max_iterations = iterations;
    summary = SolveBundle(camera, &b.problem, bo, abort_flag);
    return summary.usable;
  };
  auto apply = [&](Map& map, const MapBundle& b, bool usable) {
    if (!usable) return;
    if (still_valid && !still_valid(map)) {
      summary.usable = false;
      return;
    }
    std::map<KeyFrameId, Rigid3d> before;
    for (const auto& [id, kf] : map.keyframes()) before[id] = kf.cam_from_world;
    ApplyMapBundle(b, summary, &map);
    PropagateBundleCorrection(b, before, &map);
    if (applied) applied(map, before);
  };
  store->ComputeOutsideLock(snapshot, solve, apply);
  return summary;
}

}  // namespace detslam
