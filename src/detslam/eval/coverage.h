// Tracking coverage: which camera frames that have ground truth also have an estimated pose.
// - camera frames: the colour stamps of the dataset (rgb.txt), or the ground-truth stamps when no
//   frame list is given;
// - a frame "has ground truth" when associate.py-style greedy one-to-one matching of
//   |t_gt - (t_frame + offset)| < max_difference pairs it with a ground-truth stamp;
// - such a frame is "tracked" when the same kind of matching (no offset: estimate and frames share
//   the camera clock) pairs it with an estimated pose;
// - fraction = tracked / frames with ground truth;
// - untracked runs are maximal runs of consecutive frames-with-ground-truth that are not tracked.
//   A run's duration is t(last frame of run) - t(first frame of run) + the median interval between
//   frames-with-ground-truth, so a single dropped frame at 30 Hz counts as 1/30 s. The longest
//   run is the one with the largest duration (the earliest on a tie).
#pragma once

#include <vector>

#include "detslam/core/association.h"
#include "detslam/core/timestamp.h"

namespace detslam {

struct CoverageResult {
  size_t frames_with_gt = 0;         // camera frames associated with a ground-truth pose
  size_t frames_tracked = 0;         // of those, frames with an estimated pose
  double fraction = 0.0;             // frames_tracked / frames_with_gt (0 if none)
  size_t longest_untracked_frames = 0;   // frames in the longest untracked run
  double longest_untracked_s = 0.0;      // its duration (see above), 0 if none
  Timestamp longest_untracked_start;     // stamp of its first frame
  std::vector<Timestamp> frame_stamps;   // the frames with ground truth, in time order
  std::vector<bool> tracked;             // per frame_stamps entry
};

// `frames`, `gt` and `est` need not be sorted.
CoverageResult ComputeCoverage(const std::vector<Timestamp>& frames,
                               const std::vector<Timestamp>& gt,
                               const std::vector<Timestamp>& est,
                               const AssociationOptions& options);

}  // namespace detslam
