#include "detslam/geometry/pnp_ransac.h"

#include <algorithm>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <utility>

#include "detslam/core/check.h"
#include "detslam/geometry/ransac.h"

namespace detslam {
namespace {

constexpr int kPnpSampleSize = 4;  // AP3P: three points for the solutions, a fourth to pick one

Rigid3d FromRvecTvec(const cv::Mat& rvec, const cv::Mat& tvec) {
  const Eigen::Vector3d r(rvec.at<double>(0), rvec.at<double>(1), rvec.at<double>(2));
  const Eigen::Vector3d t(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2));
  const double angle = r.norm();
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  if (angle > 0.0) q = Eigen::Quaterniond(Eigen::AngleAxisd(angle, r / angle));
  return Rigid3d(q, t);
}

void ToRvecTvec(const Rigid3d& pose, cv::Mat* rvec, cv::Mat* tvec) {
  const Eigen::AngleAxisd aa(pose.rotation());
  const Eigen::Vector3d r = aa.angle() * aa.axis();
  *rvec = (cv::Mat_<double>(3, 1) << r.x(), r.y(), r.z());
  *tvec = (cv::Mat_<double>(3, 1) << pose.translation().x(), pose.translation().y(),
           pose.translation().z());
}

class PnpProblem {
 public:
  PnpProblem(const PinholeCamera& camera, const std::vector<Eigen::Vector3d>& points,
             const std::vector<Eigen::Vector2d>& pixels, const std::vector<double>& sigma2,
             double chi2)
      : camera_(camera),
        points_(points),
        pixels_(pixels),
        sigma2_(sigma2),
        chi2_(chi2),
        k_(camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1) {}

  // Solves on the given indices with OpenCV; false when OpenCV fails or rejects the sample.
  bool Solve(const std::vector<int>& indices, int flags, const Rigid3d* guess,
             Rigid3d* pose) const {
    std::vector<cv::Point3d> obj;
    std::vector<cv::Point2d> img;
    obj.reserve(indices.size());
    img.reserve(indices.size());
    for (const int i : indices) {
      obj.emplace_back(points_[i].x(), points_[i].y(), points_[i].z());
      img.emplace_back(pixels_[i].x(), pixels_[i].y());
    }
    cv::Mat rvec, tvec;
    if (guess != nullptr) ToRvecTvec(*guess, &rvec, &tvec);
    try {
      if (!cv::solvePnP(obj, img, k_, cv::noArray(), rvec, tvec, guess != nullptr, flags)) {
        return false;
      }
    } catch (const cv::Exception&) {
      return false;  // degenerate minimal sample (e.g. collinear points)
    }
    if (rvec.empty() || tvec.empty()) return false;
    rvec.convertTo(rvec, CV_64F);
    tvec.convertTo(tvec, CV_64F);
    *pose = FromRvecTvec(rvec, tvec);
    return pose->translation().allFinite() && pose->rotation().coeffs().allFinite();
  }

  int Classify(const Rigid3d& pose, std::vector<bool>* inliers) const {
    inliers->assign(points_.size(), false);
    int count = 0;
    for (size_t i = 0; i < points_.size(); ++i) {
      const Eigen::Vector3d p_cam = pose * points_[i];
      if (p_cam.z() <= 0.0) continue;
      const double s2 = sigma2_.empty() ? 1.0 : sigma2_[i];
      if ((camera_.Project(p_cam) - pixels_[i]).squaredNorm() / s2 < chi2_) {
        (*inliers)[i] = true;
        ++count;
      }
    }
    return count;
  }

 private:
  const PinholeCamera& camera_;
  const std::vector<Eigen::Vector3d>& points_;
  const std::vector<Eigen::Vector2d>& pixels_;
  const std::vector<double>& sigma2_;
  double chi2_;
  cv::Matx33d k_;
};

}  // namespace

PnpResult SolvePnpRansac(const PinholeCamera& camera,
                         const std::vector<Eigen::Vector3d>& points_world,
                         const std::vector<Eigen::Vector2d>& pixels,
                         const std::vector<double>& sigma2, const RansacOptions& options,
                         Rng& rng) {
  std::string error;
  if (!options.Check(&error)) throw InputError("SolvePnpRansac options: " + error);
  if (points_world.size() != pixels.size() || (!sigma2.empty() && sigma2.size() != pixels.size())) {
    throw InputError("SolvePnpRansac: points, pixels and sigma2 sizes differ");
  }
  for (const double s2 : sigma2) {
    if (!(s2 > 0.0)) throw InputError("SolvePnpRansac: sigma2 must be positive");
  }
  const PnpProblem problem(camera, points_world, pixels, sigma2, options.chi2_threshold);
  RansacOutcome<Rigid3d> outcome = RunRansac<Rigid3d>(
      static_cast<int>(points_world.size()), kPnpSampleSize,
      std::max(kPnpSampleSize, options.min_inliers), options, rng,
      [&](const std::vector<int>& sample, Rigid3d* pose) {
        return problem.Solve(sample, cv::SOLVEPNP_AP3P, nullptr, pose);
      },
      [&](const Rigid3d& pose, std::vector<bool>* inliers) {
        return problem.Classify(pose, inliers);
      },
      [&](const std::vector<int>& inliers, const Rigid3d& start, Rigid3d* refined) {
        return problem.Solve(inliers, cv::SOLVEPNP_ITERATIVE, &start, refined);
      });
  return ToRansacResult(std::move(outcome), &PnpResult::cam_from_world);
}

}  // namespace detslam
