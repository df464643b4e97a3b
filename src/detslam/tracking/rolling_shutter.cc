#include "detslam/tracking/rolling_shutter.h"

#include <algorithm>
#include <vector>

namespace detslam {

double RowTimeOffset(const PinholeCamera& camera, double y) {
  if (camera.height <= 1) return 0.0;
  return (y / (camera.height - 1) - 0.5) * camera.rolling_shutter_readout;
}

Twist TwistPerSecond(const Rigid3d& later_from_earlier, double seconds) {
  if (!(seconds > 0)) return Twist::Zero();
  return later_from_earlier.Log() / seconds;
}

std::shared_ptr<const FrameFeatures> CompensateRollingShutter(
    const PinholeCamera& camera, const std::shared_ptr<const FrameFeatures>& features,
    const Twist& twist_per_second) {
  if (!(camera.rolling_shutter_readout > 0) || features == nullptr || features->size() == 0)
    return features;
  const FrameFeatures& in = *features;
  auto out = std::make_shared<FrameFeatures>(in);
  std::vector<float> known;
  known.reserve(in.size());
  for (float d : in.depth)
    if (d > 0) known.push_back(d);
  double median = 0.0;
  if (!known.empty()) {
    std::nth_element(known.begin(), known.begin() + known.size() / 2, known.end());
    median = known[known.size() / 2];
  }
  for (size_t i = 0; i < in.size(); ++i) {
    const double tau = RowTimeOffset(camera, in.keypoints[i].pt.y);
    // stamp_from_row = cam(0)_from_cam(tau) = Exp(tau * xi)^-1.
    const Rigid3d stamp_from_row = Rigid3d::Exp(-tau * twist_per_second);
    const bool has_depth = in.depth[i] > 0;
    if (!has_depth && median <= 0) {
      // No depth anywhere: the rotation alone (a point at infinity).
      const Eigen::Vector3d ray = camera.Unproject(in.undist[i], 1.0);
      const Eigen::Vector3d r = stamp_from_row.rotation() * ray;
      if (r.z() > 0) out->undist[i] = camera.Project(r);
      continue;
    }
    const Eigen::Vector3d p_row = camera.Unproject(in.undist[i], has_depth ? in.depth[i] : median);
    const Eigen::Vector3d p = stamp_from_row * p_row;
    if (!(p.z() > 0)) continue;
    out->undist[i] = camera.Project(p);
    if (has_depth) {
      out->depth[i] = static_cast<float>(p.z());
      out->u_right[i] = static_cast<float>(out->undist[i].x() - camera.bf / p.z());
    }
  }
  out->grid = MakeKeypointGrid(camera, out->keypoints, out->undist);
  return out;
}

}  // namespace detslam
