// Pinhole RGB-D camera: intrinsics, Brown-Conrady distortion (k1 k2 p1 p2 k3, OpenCV order) and
// the depth conventions of an RGB-D sensor (depth scale, virtual stereo baseline, close/far split).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace detslam {

struct PinholeCamera {
  int width = 640;                                // image width in pixels
  int height = 480;                               // image height in pixels
  double fx = 535.4;                              // focal length x (pixels)
  double fy = 539.2;                              // focal length y (pixels)
  double cx = 320.1;                              // principal point x (pixels)
  double cy = 247.6;                              // principal point y (pixels)
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0;  // distortion (OpenCV order)
  double fps = 30.0;                              // frame rate (Hz)
  double depth_map_factor = 5000.0;               // depth PNG value per metre
  double bf = 40.0;        // virtual stereo baseline times fx (pixels * metres)
  double th_depth = 40.0;  // close/far threshold in baselines (ORB-SLAM's ThDepth)
  // Depth noise as a virtual-stereo disparity bf / depth (pixels): an RGB-D observation's third
  // residual is its disparity error over this (Kinect-class sensors: about bf * 1.4e-3 = 0.06 px,
  // nearly constant with depth). 0: ORB-SLAM3's u_right error with the keypoint's octave sigma,
  // which weights depth like a pixel of the image and so about 100-300 times below its accuracy.
  double disparity_sigma = 0.1;
  bool rgb_order = true;  // true if colour images are RGB (Camera.RGB: 1)
  // Rolling shutter: seconds from the first image row's exposure to the last one's, the middle
  // row exposed at the frame's stamp (Camera.RollingShutterReadout; 0: a global shutter, as
  // ORB-SLAM3 assumes). Tracking then moves each keypoint to where the camera at the frame's stamp
  // saw its point (tracking/rolling_shutter.h).
  double rolling_shutter_readout = 0.0;

  bool Check(std::string* error) const;
  bool HasDistortion() const { return k1 != 0 || k2 != 0 || p1 != 0 || p2 != 0 || k3 != 0; }
  double Baseline() const { return bf / fx; }
  // Depth in metres under which a point counts as close (ORB-SLAM's mThDepth).
  double CloseDepthThreshold() const { return Baseline() * th_depth; }

  // Projects a point in camera coordinates (z > 0) to undistorted pixel coordinates.
  Eigen::Vector2d Project(const Eigen::Vector3d& p_cam) const {
    return {fx * p_cam.x() / p_cam.z() + cx, fy * p_cam.y() / p_cam.z() + cy};
  }
  // Back-projects an undistorted pixel with depth z (metres) to camera coordinates.
  Eigen::Vector3d Unproject(const Eigen::Vector2d& uv, double z) const {
    return {(uv.x() - cx) / fx * z, (uv.y() - cy) / fy * z, z};
  }
  bool InImage(const Eigen::Vector2d& uv, double border = 0.0) const {
    return uv.x() >= border && uv.y() >= border && uv.x() < width - border &&
           uv.y() < height - border;
  }
  // Applies lens distortion to undistorted pixel coordinates (the Brown-Conrady model OpenCV
  // uses; identity without distortion): where an undistorted projection lies in the image.
  Eigen::Vector2d Distort(const Eigen::Vector2d& undistorted) const;
  // Removes lens distortion from pixel coordinates (identity without distortion).
  std::vector<Eigen::Vector2d> Undistort(const std::vector<Eigen::Vector2d>& distorted) const;
};

}  // namespace detslam
