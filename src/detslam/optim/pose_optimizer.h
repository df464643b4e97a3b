// Motion-only optimisation of one camera pose against fixed world points (ORB-SLAM's
// PoseOptimization): several rounds of Levenberg-Marquardt on SE(3) with Huber kernels; after each
// round every observation is re-classified by its chi2; the last round runs without the kernel.
// Hand-written (analytic 6-DoF Jacobians, left perturbation cam_from_world <- Exp(delta) * pose):
// it runs on every frame and is much faster than a general solver on a 6-parameter problem.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "detslam/core/camera.h"
#include "detslam/core/rigid3d.h"

namespace detslam {

struct PoseObservation {
  Eigen::Vector3d point_world = Eigen::Vector3d::Zero();  // fixed landmark position
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();           // undistorted keypoint (pixels)
  double u_right = -1;    // virtual right-camera u (u - bf / depth); < 0: mono observation
  double inv_sigma2 = 1;  // information scale of the keypoint's octave (1 / sigma^2)
};

struct PoseOptimizerOptions {
  int rounds = 4;                 // classify-and-optimise rounds (the last one without Huber)
  int iterations_per_round = 10;  // LM iterations per round
  double chi2_mono = 5.991;       // inlier threshold for (u, v) residuals (chi2, 2 dof, 95%)
  double chi2_stereo = 7.815;     // inlier threshold for (u, v, u_right) residuals (3 dof, 95%)

  bool Check(std::string* error) const;
};

struct PoseOptimizerResult {
  Rigid3d cam_from_world;     // optimised pose
  std::vector<bool> inliers;  // per observation, after the last classification
  int num_inliers = 0;
};

// Starts with every observation an inlier. Observations behind the camera are outliers.
// Throws InputError on invalid options.
PoseOptimizerResult OptimizePose(const PinholeCamera& camera, const Rigid3d& initial_cam_from_world,
                                 const std::vector<PoseObservation>& observations,
                                 const PoseOptimizerOptions& options);

// d(u, v, u_right) / d(delta) of the stereo projection of p_cam = cam_from_world * p_world under
// the left perturbation cam_from_world <- Exp(delta) * cam_from_world, delta = (rho, phi), at
// delta = 0. The first two rows are the mono Jacobian.
Eigen::Matrix<double, 3, 6> StereoPoseJacobian(const PinholeCamera& camera,
                                               const Eigen::Vector3d& p_cam);

}  // namespace detslam
