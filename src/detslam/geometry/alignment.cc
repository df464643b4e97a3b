#include "detslam/geometry/alignment.h"

#include <Eigen/SVD>

#include "detslam/core/check.h"

namespace detslam {

Alignment AlignPointSets(const std::vector<Eigen::Vector3d>& a,
                         const std::vector<Eigen::Vector3d>& b, bool with_scale) {
  DETSLAM_CHECK_MSG(a.size() == b.size(),
                    "point sets differ in size: " << a.size() << " vs " << b.size());
  DETSLAM_CHECK_MSG(a.size() >= 3, "need at least 3 point pairs, got " << a.size());
  const double n = static_cast<double>(a.size());
  Eigen::Vector3d mean_a = Eigen::Vector3d::Zero();
  Eigen::Vector3d mean_b = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < a.size(); ++i) {
    mean_a += a[i];
    mean_b += b[i];
  }
  mean_a /= n;
  mean_b /= n;

  Eigen::Matrix3d sigma = Eigen::Matrix3d::Zero();
  double var_a = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    const Eigen::Vector3d da = a[i] - mean_a;
    sigma += (b[i] - mean_b) * da.transpose();
    var_a += da.squaredNorm();
  }
  sigma /= n;
  var_a /= n;

  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(sigma, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Vector3d s_diag(1.0, 1.0, 1.0);
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) s_diag.z() = -1.0;
  const Eigen::Matrix3d rotation = svd.matrixU() * s_diag.asDiagonal() * svd.matrixV().transpose();

  Alignment out;
  if (with_scale) {
    DETSLAM_CHECK_MSG(var_a > 0.0, "scale alignment needs source points with non-zero spread");
    out.scale = svd.singularValues().dot(s_diag) / var_a;
  }
  out.b_from_a = Rigid3d(rotation, mean_b - out.scale * (rotation * mean_a));
  return out;
}

Rigid3d AlignPoseSets(const std::vector<Rigid3d>& a, const std::vector<Rigid3d>& b) {
  DETSLAM_CHECK(a.size() == b.size() && !a.empty());
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < a.size(); ++i) sum += b[i].RotationMatrix() * a[i].RotationMatrix().transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(sum, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d fix = Eigen::Matrix3d::Identity();
  fix(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  const Eigen::Matrix3d R = svd.matrixU() * fix * svd.matrixV().transpose();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < a.size(); ++i) t += b[i].translation() - R * a[i].translation();
  return Rigid3d(R, t / static_cast<double>(a.size()));
}

}  // namespace detslam
