// Helpers shared by the dense module's tests (header-only).
#pragma once

#include <opencv2/core.hpp>

#include "detslam/core/camera.h"
#include "detslam/dense/tsdf_volume.h"

namespace detslam::dense_test {

// A 160x120 pinhole camera without distortion (f = 140 px).
inline PinholeCamera SmallCamera() {
  PinholeCamera c;
  c.width = 160;
  c.height = 120;
  c.fx = c.fy = 140.0;
  c.cx = 79.5;
  c.cy = 59.5;
  return c;
}

// 2 cm voxels, 8 cm truncation: coarse enough for quick tests.
inline TsdfOptions CoarseOptions() {
  TsdfOptions o;
  o.voxel_m = 0.02;
  o.truncation_m = 0.08;
  return o;
}

// Depth of the plane z = z0 + slope * x (camera frame, camera at the origin) for every pixel.
inline cv::Mat PlaneDepth(const PinholeCamera& c, double z0, double slope) {
  cv::Mat d(c.height, c.width, CV_32FC1);
  for (int v = 0; v < c.height; ++v) {
    for (int u = 0; u < c.width; ++u) {
      const double a = (u - c.cx) / c.fx;
      d.at<float>(v, u) = static_cast<float>(z0 / (1.0 - slope * a));
    }
  }
  return d;
}

}  // namespace detslam::dense_test
