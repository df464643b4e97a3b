// The Huber kernel the hand-written Levenberg-Marquardt solvers share (pose_optimizer.cc,
// schur_bundle.cc): the same kernel as ceres::HuberLoss(delta).
#pragma once

#include <cmath>

namespace detslam {

// Huber cost rho(s) of the squared whitened norm s and the IRLS weight rho'(s); without the
// kernel (robust false) the cost is s and the weight 1.
inline void Robustify(double s, double delta, bool robust, double* cost, double* weight) {
  if (!robust || s <= delta * delta) {
    *cost = s;
    *weight = 1.0;
    return;
  }
  const double e = std::sqrt(s);
  *cost = 2.0 * delta * e - delta * delta;
  *weight = delta / e;
}

}  // namespace detslam
