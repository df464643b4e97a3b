// Options shared by the RANSAC estimators (PnP, 3-D rigid).
#pragma once

#include <string>

namespace detslam {

struct RansacOptions {
  int max_iterations = 300;       // upper bound on minimal-sample hypotheses
  double probability = 0.99;      // confidence for the adaptive iteration count
  int min_inliers = 10;           // fewer inliers than this -> success = false
  double chi2_threshold = 5.991;  // PnP inlier test on squared pixel error / sigma2 (chi2, 2 dof)

  bool Check(std::string* error) const;
};

// Number of RANSAC iterations needed to draw one all-inlier sample of size sample_size with the
// given confidence when a fraction inlier_ratio of the data are inliers, capped at max_iterations.
int AdaptiveIterations(double inlier_ratio, int sample_size, double probability,
                       int max_iterations);

}  // namespace detslam
