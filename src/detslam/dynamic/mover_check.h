// The Det-SLAM stage's geometric check for movers the segmenter missed (see mover_check.cc for
// the method). A pure function: the tracker supplies the optimised pose, each keypoint's
// associated 3-D point and the previous frame, and re-optimises the pose after it.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "detslam/core/camera.h"
#include "detslam/dynamic/geometric_check.h"
#include "detslam/map/frame.h"

namespace detslam {

// Labels movers in `labels` (one per keypoint of `frame`, kGeometric for the new ones; other
// non-static labels are kept) and returns how many it labelled. `frame`: features,
// cam_from_world (set) and landmarks (kNoLandmark = unmatched); `points[i]`: the 3-D point
// keypoint i was associated with at this pose (a landmark, or one the pose optimiser rejected),
// if any; `last_frame`: the previous tracked frame with its labels, or null.
int LabelMovers(const PinholeCamera& camera, const ScaleInfo& scale,
                const MoverCheckOptions& options, const Frame& frame,
                const std::vector<std::optional<Eigen::Vector3d>>& points, const Frame* last_frame,
                std::vector<KeypointLabel>* labels);

}  // namespace detslam
