// Tracker: runs the Det-SLAM stage's geometric check (dynamic/mover_check.h) on a tracked frame
// and drops the map associations of the movers it labels.
#include <spdlog/spdlog.h>

#include <algorithm>

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
  // Keypoints in the regions of the last frames' movers first, so that they stay out of the
  // robust statistics too; new regions only from this frame's confirmed movers (a region never
  // renews itself, nor grows over the static scene by the labels spread around movers).
  int labelled = 0;
  if (movers_.region_frames > 0) {
    mover_regions_.erase(
        std::remove_if(mover_regions_.begin(), mover_regions_.end(),
                       [&](const MoverRegion& r) {
                         return frame->index - r.frame > movers_.region_frames ||
                                frame->index < r.frame;
                       }),
        mover_regions_.end());
    labelled += LabelInMoverRegions(mover_regions_, movers_, *frame, &frame->labels);
    spdlog::debug("frame {}: {} keypoints in {} mover regions", frame->index, labelled,
                  mover_regions_.size());
  }
  std::vector<size_t> confirmed;
  labelled += LabelMovers(camera_, map.scale(), movers_, *frame, points,
                          last_frame_ ? &*last_frame_ : nullptr, &frame->labels, &confirmed);
  if (movers_.region_frames > 0) {
    std::vector<KeypointLabel> found(n, KeypointLabel::kStatic);
    for (size_t i : confirmed) found[i] = KeypointLabel::kGeometric;
    for (const MoverRegion& r : MoverRegionsOf(movers_, *frame, found)) {
      spdlog::debug("frame {}: mover region u {:.0f}-{:.0f} v {:.0f}-{:.0f} depth {:.2f}-{:.2f}",
                    frame->index, r.min_u, r.max_u, r.min_v, r.max_v, r.min_depth, r.max_depth);
      mover_regions_.push_back(r);
    }
  }

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
