#include "detslam/mapping/map_bundle.h"

#include <map>
#include <set>

namespace detslam {

MapBundle BuildMapBundle(const Map& map, const std::vector<KeyFrameId>& free,
                         const std::vector<KeyFrameId>& fixed) {
  MapBundle b;
  const KeyFrameId origin = map.first_keyframe();
  std::map<KeyFrameId, size_t> pose_index;
  auto add_pose = [&](KeyFrameId k, bool is_fixed) {
    if (pose_index.count(k)) return;
    pose_index[k] = b.problem.poses.size();
    b.problem.poses.push_back({k, map.keyframe(k).cam_from_world, is_fixed || k == origin});
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

BundleSummary GlobalBundleAdjustment(const PinholeCamera& camera, int iterations, Map* map) {
  std::vector<KeyFrameId> all;
  for (const auto& [id, kf] : map->keyframes()) {
    (void)kf;
    all.push_back(id);
  }
  MapBundle b = BuildMapBundle(*map, all, {});
  BundleSummary s;
  if (b.problem.poses.empty() || b.problem.observations.empty()) return s;
  BundleOptions bo;
  bo.max_iterations = iterations;
  s = SolveBundle(camera, &b.problem, bo);
  if (s.usable) ApplyMapBundle(b, s, map);
  return s;
}

}  // namespace detslam
