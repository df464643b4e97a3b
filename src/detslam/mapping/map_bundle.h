// Bundle adjustment over part of the map: builds the solver's plain problem from keyframes and
// their landmarks, and applies a solved problem back (local BA of the local mapper, global BA
// after loop closing).
#pragma once

#include <utility>
#include <vector>

#include "detslam/core/camera.h"
#include "detslam/map/map.h"
#include "detslam/optim/bundle_adjustment.h"

namespace detslam {

struct MapBundle {
  BundleProblem problem;
  std::vector<std::pair<LandmarkId, KeyFrameId>> observation_ref;  // per problem observation
};

// Poses: `free` keyframes (optimised, except the map's first keyframe, which anchors the gauge)
// then `fixed` ones; points: every landmark seen by a free keyframe, with its observations in
// any keyframe of the problem. Returns an empty problem when nothing would be fixed (no gauge).
MapBundle BuildMapBundle(const Map& map, const std::vector<KeyFrameId>& free,
                         const std::vector<KeyFrameId>& fixed);

// Writes a solved bundle back: erases the observations the solver marked as outliers, sets the
// free poses and the points (updating their geometry). Keyframes or landmarks removed meanwhile
// are skipped. Returns the number of observations erased.
int ApplyMapBundle(const MapBundle& bundle, const BundleSummary& summary, Map* map);

// Bundle adjustment of the whole map (first keyframe fixed); returns the solver summary.
BundleSummary GlobalBundleAdjustment(const PinholeCamera& camera, int iterations, Map* map);

}  // namespace detslam
