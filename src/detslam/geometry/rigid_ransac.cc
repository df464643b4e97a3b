#include "detslam/geometry/rigid_ransac.h"

#include <Eigen/SVD>
#include <algorithm>
#include <string>

#include "detslam/core/check.h"

namespace detslam {
namespace {

constexpr int kSampleSize = 3;

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
  RigidRansacResult result;
  const int n = static_cast<int>(a.size());
  result.inliers.assign(n, false);
  if (n < std::max(kSampleSize, options.min_inliers)) return result;

  int best_count = -1;
  Rigid3d best;
  std::vector<bool> mask;
  int needed = options.max_iterations;
  std::vector<int> sample;
  while (result.iterations < needed) {
    ++result.iterations;
    sample.clear();
    while (static_cast<int>(sample.size()) < kSampleSize) {
      const int i = rng.UniformInt(0, n - 1);
      if (std::find(sample.begin(), sample.end(), i) == sample.end()) sample.push_back(i);
    }
    Rigid3d hypothesis;
    if (!FitRigidKabsch(a, b, sample, &hypothesis)) continue;
    const int count = Classify(a, b, hypothesis, inlier_threshold_m, &mask);
    if (count > best_count) {
      best_count = count;
      best = hypothesis;
      needed = AdaptiveIterations(static_cast<double>(count) / n, kSampleSize, options.probability,
                                  options.max_iterations);
    }
  }
  if (best_count < kSampleSize) return result;

  std::vector<bool> best_mask;
  Classify(a, b, best, inlier_threshold_m, &best_mask);
  for (int refit = 0; refit < 3; ++refit) {
    std::vector<int> indices;
    for (int i = 0; i < n; ++i) {
      if (best_mask[i]) indices.push_back(i);
    }
    Rigid3d refined;
    if (!FitRigidKabsch(a, b, indices, &refined)) break;
    const int count = Classify(a, b, refined, inlier_threshold_m, &mask);
    if (count < best_count) break;
    const bool same = (mask == best_mask);
    best = refined;
    best_mask = mask;
    best_count = count;
    if (same) break;
  }
  result.b_from_a = best;
  result.inliers = best_mask;
  result.num_inliers = best_count;
  result.success = best_count >= options.min_inliers;
  return result;
}

}  // namespace detslam
