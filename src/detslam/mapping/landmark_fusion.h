// Fusing duplicated landmarks into a keyframe (ORB-SLAM's Fuse): landmarks are projected into the
// keyframe at a given pose and matched by descriptor near their projection; a match either adds
// the observation (free keypoint) or merges the two landmarks (keypoint already has one).
#pragma once

#include <vector>

#include "detslam/core/camera.h"
#include "detslam/map/map.h"
#include "detslam/map/projection_search.h"

namespace detslam {

enum class FuseWinner {
  kMoreObserved,  // local mapping: the landmark with more observations survives
  kSource,        // loop closing: the projected (loop-side) landmark survives
};

// Projects `sources` (landmarks not yet observed by `into`) into keyframe `into` seen from
// `cam_from_world` and fuses every match. Returns the number of observations added or landmarks
// merged. Sources erased by an earlier merge are skipped.
int FuseLandmarksInto(const PinholeCamera& camera, Map& map, KeyFrameId into,
                      const std::vector<LandmarkId>& sources, const Rigid3d& cam_from_world,
                      const ProjectionSearchOptions& options, FuseWinner winner);

}  // namespace detslam
