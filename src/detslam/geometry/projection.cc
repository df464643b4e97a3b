#include "detslam/geometry/projection.h"

namespace detslam {

Eigen::Vector3d ProjectStereo(const PinholeCamera& camera, const Eigen::Vector3d& p_cam) {
  const double inv_z = 1.0 / p_cam.z();
  const double u = camera.fx * p_cam.x() * inv_z + camera.cx;
  const double v = camera.fy * p_cam.y() * inv_z + camera.cy;
  return {u, v, u - camera.bf * inv_z};
}

}  // namespace detslam
