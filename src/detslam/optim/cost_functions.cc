#include "detslam/optim/cost_functions.h"

#include "detslam/core/rigid3d.h"

namespace detslam {

bool ReprojectionCost::Evaluate(double const* const* parameters, double* residuals,
                                double** jacobians) const {
  // The rotation as Eigen applies a quaternion (u, w) to a vector p:
  // p + 2 w (u x p) + 2 u x (u x p), differentiated in that form (exact at any q, as automatic
  // differentiation of Eigen's product would be).
  const Eigen::Map<const Eigen::Vector3d> u(parameters[0]);
  const double w = parameters[0][3];
  const Eigen::Map<const Eigen::Vector3d> t(parameters[1]);
  const Eigen::Map<const Eigen::Vector3d> p(parameters[2]);
  const Eigen::Vector3d uxp = u.cross(p);
  const Eigen::Vector3d p_cam = p + 2.0 * w * uxp + 2.0 * u.cross(uxp) + t;
  const double inv_z = 1.0 / p_cam.z();
  const double u_img = k_.fx * p_cam.x() * inv_z + k_.cx;
  residuals[0] = sqrt_info_ * (u_img - obs_[0]);
  residuals[1] = sqrt_info_ * (k_.fy * p_cam.y() * inv_z + k_.cy - obs_[1]);
  const bool disparity = k_.disparity_sigma > 0;
  if (!stereo_) {
    residuals[2] = 0.0;
  } else if (disparity) {
    residuals[2] = (k_.bf * inv_z - (obs_[0] - obs_[2])) / k_.disparity_sigma;
  } else {
    residuals[2] = sqrt_info_ * (u_img - k_.bf * inv_z - obs_[2]);
  }
  if (jacobians == nullptr) return true;

  // d residual / d p_cam.
  const double inv_z2 = inv_z * inv_z;
  Eigen::Matrix3d d_pc = Eigen::Matrix3d::Zero();
  d_pc(0, 0) = sqrt_info_ * k_.fx * inv_z;
  d_pc(0, 2) = -sqrt_info_ * k_.fx * p_cam.x() * inv_z2;
  d_pc(1, 1) = sqrt_info_ * k_.fy * inv_z;
  d_pc(1, 2) = -sqrt_info_ * k_.fy * p_cam.y() * inv_z2;
  if (stereo_ && disparity) {
    d_pc(2, 2) = -k_.bf * inv_z2 / k_.disparity_sigma;
  } else if (stereo_) {
    d_pc(2, 0) = d_pc(0, 0);
    d_pc(2, 2) = d_pc(0, 2) + sqrt_info_ * k_.bf * inv_z2;
  }
  if (jacobians[0] != nullptr) {
    // d p_cam / d u = -2 w [p]x + 2 (u.p) I + 2 u p^T - 4 p u^T; d p_cam / d w = 2 (u x p).
    Eigen::Matrix<double, 3, 4> d_q;
    d_q.leftCols<3>() = -2.0 * w * Hat(p) + 2.0 * u.dot(p) * Eigen::Matrix3d::Identity() +
                        2.0 * u * p.transpose() - 4.0 * p * u.transpose();
    d_q.col(3) = 2.0 * uxp;
    Eigen::Map<Eigen::Matrix<double, 3, 4, Eigen::RowMajor>> j_q(jacobians[0]);
    j_q = d_pc * d_q;
  }
  if (jacobians[1] != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> j_t(jacobians[1]);
    j_t = d_pc;
  }
  if (jacobians[2] != nullptr) {
    // d p_cam / d p = I + 2 w [u]x + 2 [u]x^2 (the rotation matrix for a unit q).
    const Eigen::Matrix3d su = Hat(u);
    const Eigen::Matrix3d d_p = Eigen::Matrix3d::Identity() + 2.0 * w * su + 2.0 * su * su;
    Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> j_p(jacobians[2]);
    j_p = d_pc * d_p;
  }
  return true;
}

ceres::CostFunction* StereoReprojectionCost::Create(const StereoIntrinsics& k,
                                                    const Eigen::Vector3d& observed_uvr,
                                                    double sqrt_info) {
  const double obs[3] = {observed_uvr.x(), observed_uvr.y(), observed_uvr.z()};
  return new ReprojectionCost(k, obs, sqrt_info, true);
}

ceres::CostFunction* MonoReprojectionCost::Create(const StereoIntrinsics& k,
                                                  const Eigen::Vector2d& observed_uv,
                                                  double sqrt_info) {
  const double obs[3] = {observed_uv.x(), observed_uv.y(), 0.0};
  return new ReprojectionCost(k, obs, sqrt_info, false);
}

}  // namespace detslam
