// Reprojection of camera-frame points for the RGB-D (virtual stereo) model.
#pragma once

#include <Eigen/Core>

#include "detslam/core/camera.h"

namespace detslam {

// Projects a camera-frame point (z > 0) to (u, v, u_right), where u_right = u - bf / z is the
// horizontal coordinate in the virtual right camera of the RGB-D sensor.
Eigen::Vector3d ProjectStereo(const PinholeCamera& camera, const Eigen::Vector3d& p_cam);

// Normalised image coordinates (x/z, y/z) of an undistorted pixel.
inline Eigen::Vector2d PixelToNormalized(const PinholeCamera& camera, const Eigen::Vector2d& uv) {
  return {(uv.x() - camera.cx) / camera.fx, (uv.y() - camera.cy) / camera.fy};
}

}  // namespace detslam
