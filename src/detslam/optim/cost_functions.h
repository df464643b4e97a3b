// Ceres reprojection residuals for the RGB-D (virtual stereo) and monocular observation models.
// Parameter layout: rotation quaternion of cam_from_world in Eigen order [x, y, z, w] (use
// ceres::EigenQuaternionManifold), translation of cam_from_world [3], point in world [3].
// Residual = sqrt_info * (projection - observation); sqrt_info = sqrt(inv_sigma2(octave)); the
// third (depth) residual as in WhitenedStereoResidual (geometry/projection.h).
#pragma once

#include <ceres/cost_function.h>

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

namespace cost_internal {

template <typename T>
Eigen::Matrix<T, 3, 1> ToCamera(const T* q_xyzw, const T* t, const T* p_world) {
  const Eigen::Map<const Eigen::Quaternion<T>> q(q_xyzw);
  const Eigen::Map<const Eigen::Matrix<T, 3, 1>> tr(t);
  const Eigen::Map<const Eigen::Matrix<T, 3, 1>> p(p_world);
  return q * p + tr;
}

// Writes the first 2 (mono) or 3 (stereo) residual entries.
template <typename T>
void ProjectResidual(const StereoIntrinsics& k, const Eigen::Matrix<T, 3, 1>& p_cam,
                     const double* observed, double sqrt_info, bool stereo, T* residual) {
  const T inv_z = T(1.0) / p_cam.z();
  const T u = T(k.fx) * p_cam.x() * inv_z + T(k.cx);
  residual[0] = T(sqrt_info) * (u - T(observed[0]));
  residual[1] = T(sqrt_info) * (T(k.fy) * p_cam.y() * inv_z + T(k.cy) - T(observed[1]));
  if (!stereo) return;
  residual[2] = k.disparity_sigma > 0
                    ? (T(k.bf) * inv_z - T(observed[0] - observed[2])) / T(k.disparity_sigma)
                    : T(sqrt_info) * (u - T(k.bf) * inv_z - T(observed[2]));
}

}  // namespace cost_internal

// (u, v, u_right) observation of a variable point from a variable pose: 3 residuals.
class StereoReprojectionCost {
 public:
  StereoReprojectionCost(const StereoIntrinsics& k, const Eigen::Vector3d& observed_uvr,
                         double sqrt_info)
      : k_(k), obs_{observed_uvr.x(), observed_uvr.y(), observed_uvr.z()}, sqrt_info_(sqrt_info) {}
  template <typename T>
  bool operator()(const T* q, const T* t, const T* p_world, T* residual) const {
    cost_internal::ProjectResidual(k_, cost_internal::ToCamera(q, t, p_world), obs_, sqrt_info_,
                                   true, residual);
    return true;
  }
  // AutoDiffCostFunction<StereoReprojectionCost, 3, 4, 3, 3>; the caller owns it.
  static ceres::CostFunction* Create(const StereoIntrinsics& k, const Eigen::Vector3d& observed_uvr,
                                     double sqrt_info);

 private:
  StereoIntrinsics k_;
  double obs_[3];
  double sqrt_info_;
};

// (u, v) observation of a variable point from a variable pose: 2 residuals.
class MonoReprojectionCost {
 public:
  MonoReprojectionCost(const StereoIntrinsics& k, const Eigen::Vector2d& observed_uv,
                       double sqrt_info)
      : k_(k), obs_{observed_uv.x(), observed_uv.y(), 0.0}, sqrt_info_(sqrt_info) {}
  template <typename T>
  bool operator()(const T* q, const T* t, const T* p_world, T* residual) const {
    cost_internal::ProjectResidual(k_, cost_internal::ToCamera(q, t, p_world), obs_, sqrt_info_,
                                   false, residual);
    return true;
  }
  // AutoDiffCostFunction<MonoReprojectionCost, 2, 4, 3, 3>; the caller owns it.
  static ceres::CostFunction* Create(const StereoIntrinsics& k, const Eigen::Vector2d& observed_uv,
                                     double sqrt_info);

 private:
  StereoIntrinsics k_;
  double obs_[3];
  double sqrt_info_;
};

}  // namespace detslam
