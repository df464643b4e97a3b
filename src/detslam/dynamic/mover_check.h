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
// if any; `last_frame`: the previous tracked frame with its labels, or null. `confirmed` (may be
// null): set to the matched movers confirmed by their neighbours (the seeds, without the
// keypoints labelled around them or carried from the last frame).
// Where the geometric check found a mover, carried to the next frames (MoverCheckOptions::
// region_frames): at camera rate the segmenter's masks of an entering person come several frames
// after the person, and meanwhile the keypoints on them that the check did not label (not yet
// matched, or beyond radius_px from a labelled one) would become landmarks and frame-to-frame
// points. A region labels the keypoints inside its box at its depth, as the Det-SLAM depth step
// does inside a detection box.
struct MoverRegion {
  int64_t frame = 0;                       // the input frame it was found in
  double min_u = 0, min_v = 0, max_u = 0, max_v = 0;  // box, undistorted pixels
  double min_depth = 0, max_depth = 0;     // metres
};

// The regions of the keypoints `labels` marks kGeometric in `frame` (the tracker passes the
// confirmed movers of LabelMovers: the keypoints it labels around them would let a region grow
// over the static scene at their depth): clusters (keypoints within
// radius_px of each other at the same depth, options.depth_ratio) of at least
// region_min_keypoints keypoints with depth, each with its bounding box and the range of its
// keypoints' depths from the 10th to the 90th percentile, widened by region_depth_ratio.
std::vector<MoverRegion> MoverRegionsOf(const MoverCheckOptions& options, const Frame& frame,
                                        const std::vector<KeypointLabel>& labels);

// Labels kGeometric the kStatic keypoints of `frame` inside one of `regions` found at most
// options.region_frames frames before it: in its box grown by radius_px + region_growth_px per
// frame since, with a depth in its range. Returns how many it labelled.
int LabelInMoverRegions(const std::vector<MoverRegion>& regions, const MoverCheckOptions& options,
                        const Frame& frame, std::vector<KeypointLabel>* labels);

int LabelMovers(const PinholeCamera& camera, const ScaleInfo& scale,
                const MoverCheckOptions& options, const Frame& frame,
                const std::vector<std::optional<Eigen::Vector3d>>& points, const Frame* last_frame,
                std::vector<KeypointLabel>* labels, std::vector<size_t>* confirmed = nullptr);

}  // namespace detslam
