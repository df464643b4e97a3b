#include "detslam/core/camera.h"

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <sstream>

namespace detslam {

bool PinholeCamera::Check(std::string* error) const {
  std::ostringstream os;
  if (width <= 0 || height <= 0)
    os << "image size must be positive (got " << width << "x" << height << "); ";
  if (!(fx > 0) || !(fy > 0)) os << "focal lengths must be positive; ";
  if (!std::isfinite(cx) || !std::isfinite(cy)) os << "principal point must be finite; ";
  if (!(depth_map_factor > 0)) os << "DepthMapFactor must be positive; ";
  if (!(bf > 0)) os << "bf (baseline * fx) must be positive; ";
  if (!(th_depth > 0)) os << "ThDepth must be positive; ";
  if (!(disparity_sigma >= 0)) os << "DisparitySigma must be >= 0; ";
  if (!(fps > 0)) os << "fps must be positive; ";
  if (!(rolling_shutter_readout >= 0) || (fps > 0 && rolling_shutter_readout > 1.0 / fps))
    os << "RollingShutterReadout must be in [0, 1/fps] seconds; ";
  if (error != nullptr) *error = os.str();
  return os.str().empty();
}

Eigen::Vector2d PinholeCamera::Distort(const Eigen::Vector2d& undistorted) const {
  if (!HasDistortion()) return undistorted;
  const double x = (undistorted.x() - cx) / fx, y = (undistorted.y() - cy) / fy;
  const double r2 = x * x + y * y;
  const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
  const double xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x);
  const double yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y;
  return {fx * xd + cx, fy * yd + cy};
}

std::vector<Eigen::Vector2d> PinholeCamera::Undistort(
    const std::vector<Eigen::Vector2d>& distorted) const {
  if (!HasDistortion() || distorted.empty()) return distorted;
  std::vector<cv::Point2f> in(distorted.size()), out;
  for (size_t i = 0; i < distorted.size(); ++i) {
    in[i] = cv::Point2f(static_cast<float>(distorted[i].x()), static_cast<float>(distorted[i].y()));
  }
  const cv::Matx33d k(fx, 0, cx, 0, fy, cy, 0, 0, 1);
  const cv::Vec<double, 5> d(k1, k2, p1, p2, k3);
  cv::undistortPoints(in, out, k, d, cv::noArray(), k);
  std::vector<Eigen::Vector2d> result(out.size());
  for (size_t i = 0; i < out.size(); ++i) result[i] = {out[i].x, out[i].y};
  return result;
}

}  // namespace detslam
