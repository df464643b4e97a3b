// Reprojection of camera-frame points for the RGB-D (virtual stereo) model.
#pragma once

#include <Eigen/Core>

#include "detslam/core/camera.h"

namespace detslam {

// Projects a camera-frame point (z > 0) to (u, v, u_right), where u_right = u - bf / z is the
// horizontal coordinate in the virtual right camera of the RGB-D sensor.
Eigen::Vector3d ProjectStereo(const PinholeCamera& camera, const Eigen::Vector3d& p_cam);

// Whitened residual (projection - observation) of an RGB-D observation (uv, u_right) of a
// camera-frame point (z > 0): the (u, v) error times sqrt_info (1 / sigma of the keypoint's
// octave) and, third, the disparity error (bf / z - (u - u_right)) over camera.disparity_sigma;
// with disparity_sigma = 0 the third entry is ORB-SLAM3's u_right error times sqrt_info. Its
// squared norm is the chi2 of the observation.
Eigen::Vector3d WhitenedStereoResidual(const PinholeCamera& camera, const Eigen::Vector3d& p_cam,
                                       const Eigen::Vector2d& uv, double u_right, double sqrt_info);

// Depth below which an observed point counts as not in front of the camera.
constexpr double kMinObservationDepth = 1e-6;

// The whitened residual of an observation (uv, u_right) of the camera-frame point p_cam in an
// optimiser: WhitenedStereoResidual, its third entry 0 for a mono observation (stereo false).
// False, r untouched, when the point is not deeper than kMinObservationDepth.
inline bool ObservationResidual(const PinholeCamera& camera, const Eigen::Vector3d& p_cam,
                                const Eigen::Vector2d& uv, double u_right, double sqrt_info,
                                bool stereo, Eigen::Vector3d* r) {
  if (!(p_cam.z() > kMinObservationDepth)) return false;
  *r = WhitenedStereoResidual(camera, p_cam, uv, u_right, sqrt_info);
  if (!stereo) (*r)(2) = 0.0;
  return true;
}

// Normalised image coordinates (x/z, y/z) of an undistorted pixel.
inline Eigen::Vector2d PixelToNormalized(const PinholeCamera& camera, const Eigen::Vector2d& uv) {
  return {(uv.x() - camera.cx) / camera.fx, (uv.y() - camera.cy) / camera.fy};
}

}  // namespace detslam
