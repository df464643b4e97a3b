// Rigid body transform between two frames, named b_from_a: it maps coordinates expressed in frame a
// into frame b. Compose so that inner frames cancel: a_from_c = a_from_b * b_from_c.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace detslam {

class Rigid3d {
 public:
  Rigid3d() : rotation_(Eigen::Quaterniond::Identity()), translation_(Eigen::Vector3d::Zero()) {}
  Rigid3d(const Eigen::Quaterniond& rotation, const Eigen::Vector3d& translation)
      : rotation_(rotation.normalized()), translation_(translation) {}
  Rigid3d(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation)
      : rotation_(Eigen::Quaterniond(rotation).normalized()), translation_(translation) {}

  static Rigid3d Identity() { return Rigid3d(); }
  // From a rotation that is already unit (e.g. read back from a file): stored bit for bit, not
  // normalised again, so that a pose survives a write-read round trip exactly.
  static Rigid3d FromUnitQuaternion(const Eigen::Quaterniond& unit, const Eigen::Vector3d& t) {
    Rigid3d r;
    r.rotation_ = unit;
    r.translation_ = t;
    return r;
  }
  // From a 4x4 homogeneous matrix (the rotation block is re-orthonormalised via the quaternion).
  static Rigid3d FromMatrix(const Eigen::Matrix4d& m) {
    return Rigid3d(Eigen::Matrix3d(m.topLeftCorner<3, 3>()),
                   Eigen::Vector3d(m.topRightCorner<3, 1>()));
  }
  // Exponential map of a twist (rho: translation part, phi: rotation vector), SE(3) convention:
  // rotation = exp(phi), translation = J(phi) * rho.
  static Rigid3d Exp(const Eigen::Matrix<double, 6, 1>& rho_phi);

  const Eigen::Quaterniond& rotation() const { return rotation_; }
  const Eigen::Vector3d& translation() const { return translation_; }
  Eigen::Matrix3d RotationMatrix() const { return rotation_.toRotationMatrix(); }
  Eigen::Matrix4d Matrix() const;

  Rigid3d Inverse() const {
    const Eigen::Quaterniond inv = rotation_.conjugate();
    return Rigid3d(inv, -(inv * translation_));
  }
  // Logarithm: (rho, phi), the inverse of Exp.
  Eigen::Matrix<double, 6, 1> Log() const;

  // Angle of the rotation in radians, in [0, pi].
  double RotationAngle() const;

  Rigid3d operator*(const Rigid3d& b_from_c) const {
    return Rigid3d(rotation_ * b_from_c.rotation_,
                   rotation_ * b_from_c.translation_ + translation_);
  }
  Eigen::Vector3d operator*(const Eigen::Vector3d& p_a) const {
    return rotation_ * p_a + translation_;
  }

 private:
  Eigen::Quaterniond rotation_;
  Eigen::Vector3d translation_;
};

// Skew-symmetric matrix such that Hat(a) * b = a x b.
Eigen::Matrix3d Hat(const Eigen::Vector3d& v);

}  // namespace detslam
