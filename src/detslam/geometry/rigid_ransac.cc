#include "detslam/geometry/rigid_ransac.h"

#include <Eigen/SVD>
#include <string>
#include <utility>

#include "detslam/core/check.h"
#include "detslam/geometry/ransac.h"

namespace detslam {
namespace {

constexpr int kRigidSampleSize = 3;

int Classify(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b,
             const Rigid3d& b_from_a, double threshold, std::vector<bool>* inliers) {
  inliers->assign(a.size(), false);
  const double t2 = threshold * threshold;
  int count = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    if ((b[i] - b_from_a * a[i]).squaredNorm() < t2) {
      (*inliers)[i] = true;
      ++count;
    }
  }
  return count;
}

}  // namespace

bool FitRigidKabsch(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b,
                    const std::vector<int>& indices, Rigid3d* b_from_a) {
  if (indices.size() < 3) return false;
  Eigen::Vector3d mean_a = Eigen::Vector3d::Zero(), mean_b = Eigen::Vector3d::Zero();
  for (const int i : indices) {
    mean_a += a[i];
    mean_b += b[i];
  }
  mean_a /= static_cast<double>(indices.size());
  mean_b /= static_cast<double>(indices.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();  // sum (b - mean_b)(a - mean_a)^T
  double spread = 0.0;
  for (const int i : indices) {
    cov += (b[i] - mean_b) * (a[i] - mean_a).transpose();
    spread += (a[i] - mean_a).squaredNorm();
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d sv = svd.singularValues();
  // Two vanishing singular values: the points are collinear and the rotation is undetermined.
  if (!(spread > 0.0) || sv(1) <= 1e-9 * sv(0) || !sv.allFinite()) return false;
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0) d(2, 2) = -1.0;
  const Eigen::Matrix3d r = svd.matrixU() * d * svd.matrixV().transpose();
  *b_from_a = Rigid3d(r, mean_b - r * mean_a);
  return true;
}

RigidRansacResult EstimateRigidRansac(const std::vector<Eigen::Vector3d>& a,
                                      const std::vector<Eigen::Vector3d>& b,
                                      double inlier_threshold_m, const RansacOptions& options,
                                      Rng& rng) {
  std::string error;
  if (!options.Check(&error)) throw InputError("EstimateRigidRansac options: " + error);
  if (a.size() != b.size()) throw InputError("EstimateRigidRansac: point set sizes differ");
  if (!(inlier_threshold_m > 0.0)) {
    throw InputError("EstimateRigidRansac: inlier threshold must be positive");
  }
  RansacOutcome<Rigid3d> outcome = RunRansac<Rigid3d>(
      static_cast<int>(a.size()), kRigidSampleSize, kRigidSampleSize, options, rng,
      [&](const std::vector<int>& sample, Rigid3d* b_from_a) {
        return FitRigidKabsch(a, b, sample, b_from_a);
      },
      [&](const Rigid3d& b_from_a, std::vector<bool>* inliers) {
        return Classify(a, b, b_from_a, inlier_threshold_m, inliers);
      },
      [&](const std::vector<int>& inliers, const Rigid3d& /*start*/, Rigid3d* b_from_a) {
        return FitRigidKabsch(a, b, inliers, b_from_a);
      });
  return ToRansacResult(std::move(outcome), &RigidRansacResult::b_from_a);
}

}  // namespace detslam
