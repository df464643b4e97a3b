// Ceres reprojection residuals for the RGB-D (virtual stereo) and monocular observation models.
// Parameter layout: rotation quaternion of cam_from_world in Eigen order [x, y, z, w] (use
// ceres::EigenQuaternionManifold), translation of cam_from_world [3], point in world [3].
// Residual = sqrt_info * (projection - observation); sqrt_info = sqrt(inv_sigma2(octave)); the
// third (depth) residual as in WhitenedStereoResidual (geometry/projection.h).
#pragma once

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "detslam/core/camera.h"

namespace detslam {

// Intrinsics as the residuals need them.
struct StereoIntrinsics {
  double fx = 0, fy = 0, cx = 0, cy = 0, bf = 0;
  double disparity_sigma = 0;  // > 0: third residual = disparity error / this (see PinholeCamera)
  static StereoIntrinsics From(const PinholeCamera& c) {
    return {c.fx, c.fy, c.cx, c.cy, c.bf, c.disparity_sigma};
  }
};

// One reprojection residual block, analytic Jacobians (the quaternion's in its 4 ambient
// coordinates, as Ceres's manifold expects). Always 3 residuals: (u, v, depth) for an observation
// with depth, (u, v, 0) without, so that every block of a bundle has the same shape and Ceres
// takes its fixed-size Schur eliminator (3, 3, 3) instead of the dynamic one. With rows of 2 and
// 3 and automatic differentiation a local bundle took about 1.5 times as long (BM_LocalBundle). The
// third residual of a mono observation and its Jacobian row are exactly 0, so the cost, its
// gradient and the normal equations are those of the 2-residual model.
class ReprojectionCost : public ceres::SizedCostFunction<3, 4, 3, 3> {
 public:
  // observed: u, v and (stereo only) the virtual right u.
  ReprojectionCost(const StereoIntrinsics& k, const double observed[3], double sqrt_info,
                   bool stereo)
      : k_(k), obs_{observed[0], observed[1], observed[2]}, sqrt_info_(sqrt_info),
        stereo_(stereo) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  StereoIntrinsics k_;
  double obs_[3];
  double sqrt_info_;
  bool stereo_;
};

// (u, v, u_right) observation of a variable point from a variable pose: 3 residuals.
struct StereoReprojectionCost {
  // The caller owns the result.
  static ceres::CostFunction* Create(const StereoIntrinsics& k, const Eigen::Vector3d& observed_uvr,
                                     double sqrt_info);
};

// (u, v) observation of a variable point from a variable pose: 2 residuals and a third that is
// always 0 (see ReprojectionCost).
struct MonoReprojectionCost {
  // The caller owns the result.
  static ceres::CostFunction* Create(const StereoIntrinsics& k, const Eigen::Vector2d& observed_uv,
                                     double sqrt_info);
};

}  // namespace detslam
