#include "detslam/geometry/projection.h"

namespace detslam {

Eigen::Vector3d ProjectStereo(const PinholeCamera& camera, const Eigen::Vector3d& p_cam) {
  const double inv_z = 1.0 / p_cam.z();
  const double u = camera.fx * p_cam.x() * inv_z + camera.cx;
  const double v = camera.fy * p_cam.y() * inv_z + camera.cy;
  return {u, v, u - camera.bf * inv_z};
}

Eigen::Vector3d WhitenedStereoResidual(const PinholeCamera& camera, const Eigen::Vector3d& p_cam,
                                       const Eigen::Vector2d& uv, double u_right,
                                       double sqrt_info) {
  const Eigen::Vector3d proj = ProjectStereo(camera, p_cam);
  const double third = camera.disparity_sigma > 0
                           ? (camera.bf / p_cam.z() - (uv.x() - u_right)) / camera.disparity_sigma
                           : sqrt_info * (proj.z() - u_right);
  return {sqrt_info * (proj.x() - uv.x()), sqrt_info * (proj.y() - uv.y()), third};
}

}  // namespace detslam
