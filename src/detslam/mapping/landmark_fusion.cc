#include "detslam/mapping/landmark_fusion.h"

namespace detslam {

int FuseLandmarksInto(const PinholeCamera& camera, Map& map, KeyFrameId into,
                      const std::vector<LandmarkId>& sources, const Rigid3d& cam_from_world,
                      const ProjectionSearchOptions& options, FuseWinner winner) {
  std::vector<ProjectionCandidate> cands;
  for (LandmarkId id : sources) {
    if (!map.HasLandmark(id)) continue;
    const Landmark& lm = map.landmark(id);
    if (lm.observations.count(into)) continue;
    cands.push_back(CandidateFromLandmark(lm));
  }
  const KeyFrame& kf = map.keyframe(into);
  const std::vector<int> m =
      SearchByProjection(camera, map.scale(), *kf.features, cam_from_world, cands, {}, options);
  int fused = 0;
  for (size_t c = 0; c < cands.size(); ++c) {
    if (m[c] < 0 || !map.HasLandmark(cands[c].landmark)) continue;
    const size_t idx = static_cast<size_t>(m[c]);
    const LandmarkId existing = map.keyframe(into).landmarks[idx];
    const LandmarkId src = cands[c].landmark;
    if (existing == src || map.landmark(src).observations.count(into)) continue;
    if (existing != kNoLandmark && map.HasLandmark(existing)) {
      const bool keep_existing =
          winner == FuseWinner::kMoreObserved &&
          map.landmark(existing).observations.size() >= map.landmark(src).observations.size();
      if (keep_existing) {
        map.ReplaceLandmark(src, existing);
      } else {
        map.ReplaceLandmark(existing, src);
      }
    } else {
      map.AddObservation(src, into, idx);
    }
    ++fused;
  }
  return fused;
}

}  // namespace detslam
