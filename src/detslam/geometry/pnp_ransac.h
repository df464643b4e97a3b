// Camera pose from 3-D/2-D correspondences: RANSAC over minimal (AP3P) samples drawn from an
// injected Rng, chi2 inlier test, refit on all inliers.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "detslam/core/camera.h"
#include "detslam/core/rigid3d.h"
#include "detslam/core/rng.h"
#include "detslam/geometry/ransac_options.h"

namespace detslam {

struct PnpResult {
  bool success = false;       // enough inliers (>= min_inliers) after the refit
  Rigid3d cam_from_world;     // best pose (refined on all inliers)
  std::vector<bool> inliers;  // per correspondence
  int num_inliers = 0;
  int iterations = 0;  // hypotheses drawn
};

// points_world[i] is seen at the undistorted pixel pixels[i] with variance sigma2[i] (pixels^2;
// empty = all 1). A correspondence is an inlier when it lies in front of the camera and
// |reprojection error|^2 / sigma2 < options.chi2_threshold. Same Rng state -> same result.
// Throws InputError on mismatched sizes or invalid options.
PnpResult SolvePnpRansac(const PinholeCamera& camera,
                         const std::vector<Eigen::Vector3d>& points_world,
                         const std::vector<Eigen::Vector2d>& pixels,
                         const std::vector<double>& sigma2, const RansacOptions& options, Rng& rng);

}  // namespace detslam
