// Rolling-shutter compensation of a frame's keypoints for RGB-D tracking. A rolling-shutter camera
// exposes its rows one after another over the readout time (PinholeCamera::rolling_shutter_readout),
// the middle row at the frame's stamp, so a moving camera sees each row from its own pose. With the
// camera's velocity over the frame (tracking's motion model), each keypoint with depth is moved to
// where the camera at the frame's stamp saw its point: its 3D point at the row's time is carried
// by the camera's motion between the two times (a constant-velocity, first-order model as in
// Hedborg et al., "Rolling shutter bundle adjustment", CVPR 2012, applied per keypoint since depth
// gives the point). A keypoint without depth moves with the median depth of the others.
#pragma once

#include <Eigen/Core>
#include <memory>

#include "detslam/core/camera.h"
#include "detslam/map/frame.h"

namespace detslam {

using Twist = Eigen::Matrix<double, 6, 1>;  // (rho, phi) per second, as Rigid3d::Exp takes it

// Seconds from the frame's stamp to the exposure of image row `y` (detected pixel row, 0 at the
// top): -readout/2 for the first row, +readout/2 for the last.
double RowTimeOffset(const PinholeCamera& camera, double y);

// The camera's motion per second from its motion over `seconds`: `later_from_earlier` maps points
// from the earlier camera frame into the later one (tracking's velocity); the twist xi gives
// cam(t + s)_from_cam(t) = Exp(s * xi).
Twist TwistPerSecond(const Rigid3d& later_from_earlier, double seconds);

// A copy of `features` with every keypoint moved to the frame's stamp (undist, depth, u_right
// and the area grid; the detected keypoints, descriptors and bag of words stay). Returns
// `features` itself when the camera has a global shutter.
std::shared_ptr<const FrameFeatures> CompensateRollingShutter(
    const PinholeCamera& camera, const std::shared_ptr<const FrameFeatures>& features,
    const Twist& twist_per_second);

}  // namespace detslam
