#include "detslam/geometry/triangulation.h"

#include <Eigen/SVD>
#include <cmath>

namespace detslam {

bool TriangulateLinear(const Rigid3d& cam1_from_world, const Rigid3d& cam2_from_world,
                       const Eigen::Vector2d& xn1, const Eigen::Vector2d& xn2,
                       Eigen::Vector3d* p_world) {
  const Eigen::Matrix<double, 3, 4> p1 = cam1_from_world.Matrix().topRows<3>();
  const Eigen::Matrix<double, 3, 4> p2 = cam2_from_world.Matrix().topRows<3>();
  Eigen::Matrix4d a;
  a.row(0) = xn1.x() * p1.row(2) - p1.row(0);
  a.row(1) = xn1.y() * p1.row(2) - p1.row(1);
  a.row(2) = xn2.x() * p2.row(2) - p2.row(0);
  a.row(3) = xn2.y() * p2.row(2) - p2.row(1);
  const Eigen::JacobiSVD<Eigen::Matrix4d> svd(a, Eigen::ComputeFullV);
  const Eigen::Vector4d x = svd.matrixV().col(3);
  // A homogeneous coordinate near zero means the rays are (close to) parallel.
  if (!x.allFinite() || std::abs(x(3)) < 1e-12 * x.head<3>().norm()) return false;
  const Eigen::Vector3d p = x.head<3>() / x(3);
  if (!p.allFinite()) return false;
  if ((cam1_from_world * p).z() <= 0.0 || (cam2_from_world * p).z() <= 0.0) return false;
  *p_world = p;
  return true;
}

double CosParallax(const Rigid3d& cam1_from_world, const Rigid3d& cam2_from_world,
                   const Eigen::Vector3d& p_world) {
  const Eigen::Vector3d c1 = cam1_from_world.Inverse().translation();
  const Eigen::Vector3d c2 = cam2_from_world.Inverse().translation();
  const Eigen::Vector3d r1 = c1 - p_world;
  const Eigen::Vector3d r2 = c2 - p_world;
  const double n = r1.norm() * r2.norm();
  if (n <= 0.0) return 1.0;
  return r1.dot(r2) / n;
}

double CosParallaxRays(const Rigid3d& cam1_from_world, const Rigid3d& cam2_from_world,
                       const Eigen::Vector2d& xn1, const Eigen::Vector2d& xn2) {
  const Eigen::Vector3d r1 = cam1_from_world.rotation().conjugate() * xn1.homogeneous();
  const Eigen::Vector3d r2 = cam2_from_world.rotation().conjugate() * xn2.homogeneous();
  return r1.dot(r2) / (r1.norm() * r2.norm());
}

}  // namespace detslam
