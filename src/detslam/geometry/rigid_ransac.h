// Rigid transform between two 3-D point sets with outliers (RANSAC over 3-point samples).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "detslam/core/rigid3d.h"
#include "detslam/core/rng.h"
#include "detslam/geometry/ransac_options.h"

namespace detslam {

struct RigidRansacResult {
  bool success = false;       // enough inliers (>= min_inliers)
  Rigid3d b_from_a;           // maps a[i] onto b[i] for the inliers
  std::vector<bool> inliers;  // per pair: |b - b_from_a * a| < inlier_threshold_m
  int num_inliers = 0;
  int iterations = 0;  // hypotheses drawn
};

// Closed-form least-squares rigid fit (Kabsch, no scale) of b_from_a on the given pairs;
// false when fewer than 3 pairs or the points are (nearly) collinear.
bool FitRigidKabsch(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b,
                    const std::vector<int>& indices, Rigid3d* b_from_a);

// RANSAC: minimal 3-point samples from rng, inliers by Euclidean distance, refit on all inliers.
// options.chi2_threshold is not used. Throws InputError on mismatched sizes or invalid options.
RigidRansacResult EstimateRigidRansac(const std::vector<Eigen::Vector3d>& a,
                                      const std::vector<Eigen::Vector3d>& b,
                                      double inlier_threshold_m, const RansacOptions& options,
                                      Rng& rng);

}  // namespace detslam
