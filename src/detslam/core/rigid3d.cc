#include "detslam/core/rigid3d.h"

#include <algorithm>
#include <cmath>

namespace detslam {
namespace {

// Left Jacobian of SO(3) and its inverse.
Eigen::Matrix3d LeftJacobian(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  const Eigen::Matrix3d h = Hat(phi);
  if (theta < 1e-8) return Eigen::Matrix3d::Identity() + 0.5 * h;
  const double t2 = theta * theta;
  return Eigen::Matrix3d::Identity() + (1.0 - std::cos(theta)) / t2 * h +
         (theta - std::sin(theta)) / (t2 * theta) * h * h;
}

Eigen::Matrix3d LeftJacobianInverse(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  const Eigen::Matrix3d h = Hat(phi);
  if (theta < 1e-8) return Eigen::Matrix3d::Identity() - 0.5 * h;
  const double t2 = theta * theta;
  const double coeff = 1.0 / t2 - (1.0 + std::cos(theta)) / (2.0 * theta * std::sin(theta));
  return Eigen::Matrix3d::Identity() - 0.5 * h + coeff * h * h;
}

}  // namespace

Eigen::Matrix3d Hat(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

Rigid3d Rigid3d::Exp(const Eigen::Matrix<double, 6, 1>& rho_phi) {
  const Eigen::Vector3d rho = rho_phi.head<3>();
  const Eigen::Vector3d phi = rho_phi.tail<3>();
  const double theta = phi.norm();
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  if (theta > 1e-12) q = Eigen::Quaterniond(Eigen::AngleAxisd(theta, phi / theta));
  return Rigid3d(q, LeftJacobian(phi) * rho);
}

Eigen::Matrix<double, 6, 1> Rigid3d::Log() const {
  const Eigen::AngleAxisd aa(rotation_);
  Eigen::Vector3d phi = aa.angle() * aa.axis();
  if (aa.angle() > M_PI) phi = (aa.angle() - 2.0 * M_PI) * aa.axis();
  Eigen::Matrix<double, 6, 1> out;
  out.head<3>() = LeftJacobianInverse(phi) * translation_;
  out.tail<3>() = phi;
  return out;
}

double Rigid3d::RotationAngle() const {
  const double w = std::clamp(std::abs(rotation_.w()), 0.0, 1.0);
  return 2.0 * std::acos(w);
}

Eigen::Matrix4d Rigid3d::Matrix() const {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = RotationMatrix();
  m.topRightCorner<3, 1>() = translation_;
  return m;
}

}  // namespace detslam
