// A geometric check for movers the detector misses: after pose prediction, keypoints matched to
// map points whose residual (reprojection error in pixels, or depth error in metres) lies far above
// that of the other static keypoints are labelled kGeometric.
//
// Robust statistics over the static keypoints with a residual: threshold =
//   max(min_threshold, median + k * 1.4826 * MAD),  MAD = median(|r - median|),
// (1.4826 * MAD estimates the standard deviation of Gaussian residuals). Static keypoints with a
// residual above the threshold become kGeometric. With fewer than `min_samples` residuals the
// statistics are not trusted and nothing is flagged.
#pragma once

#include <string>
#include <vector>

#include "detslam/map/frame.h"

namespace detslam {

struct GeometricCheckOptions {
  double k = 3.0;              // threshold in robust standard deviations above the median
  double min_threshold = 4.0;  // floor on the threshold, in the residuals' unit (e.g. pixels)
  int min_samples = 10;        // fewer static residuals than this: flag nothing

  bool Check(std::string* error) const;
};

// The tracker's geometric check as a whole (tracking/tracker_geometric.cc): the robust threshold
// above, then confirmation by flagged neighbours at the same depth, and the last frame's movers
// carried forward.
struct MoverCheckOptions {
  // On by default: it lowered the error on the walking presets where the detector misses partly
  // visible people and changed nothing on the static benchmarks (docs/BENCHMARKS.md).
  bool enabled = true;
  GeometricCheckOptions threshold;  // robust threshold on reprojection residuals (pixels / scale)
  double radius_px = 30.0;          // cluster / spread radius around a flagged keypoint
  double depth_ratio = 0.1;         // same object: depths within this fraction
  int min_cluster = 3;              // flagged neighbours needed to confirm a mover
  double carry_window_px = 15.0;    // search window for last frame's movers (pixels, level 0)
  // Mover regions (mover_check.h, MoverRegionsOf): each cluster of at least region_min_keypoints
  // labelled keypoints becomes a region (their bounding box, and their depths' 10th to 90th
  // percentile widened by region_depth_ratio) that labels the keypoints inside it at its depth in the next
  // region_frames frames, its box grown by region_growth_px per frame. 0 frames: off.
  int region_frames = 0;
  int region_min_keypoints = 4;
  double region_growth_px = 10.0;
  double region_depth_ratio = 0.1;
  // A neighbour confirms a candidate only when their residual vectors (observed minus projected
  // position) agree: differ by at most this fraction of the longer one. A moving object shifts
  // its keypoints alike; the associations the pose optimiser rejected on a static scene
  // (mismatches) point every way, and they cluster where the texture is dense. 0: off (any
  // flagged neighbour at the same depth confirms).
  double coherence = 0.0;

  bool Check(std::string* error) const;
};

struct GeometricCheckResult {
  int samples = 0;         // static keypoints with a valid residual
  double median = 0.0;     // median residual of those
  double mad = 0.0;        // median absolute deviation (unscaled)
  double threshold = 0.0;  // residuals above this are flagged (infinity when nothing is flagged)
  int flagged = 0;         // keypoints labelled kGeometric by this call
};

// Median of `values` (mean of the two middle values for an even count); 0 when empty.
double Median(std::vector<double> values);

// `residuals[i]`: keypoint i's residual against the predicted pose; negative or non-finite = none
// (unmatched). Only kStatic keypoints contribute and only they are relabelled.
// residuals.size() must equal labels->size().
GeometricCheckResult FlagGeometricOutliers(const std::vector<double>& residuals,
                                           const GeometricCheckOptions& options,
                                           std::vector<KeypointLabel>* labels);

}  // namespace detslam
