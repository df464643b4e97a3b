// Tracker: runs the Det-SLAM stage's geometric check (dynamic/mover_check.h) on a tracked frame
// and drops the map associations of the movers it labels.
#include "detslam/dynamic/mover_check.h"
#include "detslam/tracking/tracker.h"

namespace detslam {

int Tracker::ApplyGeometricCheck(const Map& map, Frame* frame, int* inliers) {
  const size_t n = frame->size();
  // Each keypoint's associated point at the optimised pose: its landmark, or the point of an
  // association the pose optimiser rejected.
  std::vector<std::optional<Eigen::Vector3d>> points(n);
  for (size_t i = 0; i < n; ++i) {
    if (frame->landmarks[i] != kNoLandmark && map.HasLandmark(frame->landmarks[i])) {
      points[i] = map.landmark(frame->landmarks[i]).position;
    } else if (scratch_.dropped[i]) {
      points[i] = scratch_.dropped_position[i];
    }
  }
  const int labelled = LabelMovers(camera_, map.scale(), movers_, *frame, points,
                                   last_frame_ ? &*last_frame_ : nullptr, &frame->labels);

  // 5. Movers must not hold map associations; re-optimise if an inlier was one.
  bool dropped_inlier = false;
  for (size_t i = 0; i < n; ++i) {
    if (frame->labels[i] == KeypointLabel::kGeometric && frame->landmarks[i] != kNoLandmark) {
      frame->landmarks[i] = kNoLandmark;
      dropped_inlier = true;
    }
  }
  if (dropped_inlier) {
    scratch_.ClearTemporaryMatches();
    *inliers = OptimizeFramePose(map, frame, false);
  }
  return labelled;
}

}  // namespace detslam
