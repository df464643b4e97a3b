#include "detslam/core/camera.h"

#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>

namespace detslam {
namespace {

TEST(PinholeCamera, DistortAgreesWithOpenCvProjectPoints) {
  PinholeCamera cam;  // TUM fr1's distortion
  cam.fx = 517.3, cam.fy = 516.5, cam.cx = 318.6, cam.cy = 255.3;
  cam.k1 = 0.2624, cam.k2 = -0.9531, cam.p1 = -0.0054, cam.p2 = 0.0026, cam.k3 = 1.1633;
  std::vector<cv::Point3d> rays;
  std::vector<Eigen::Vector2d> undistorted;
  for (double u : {5.0, 160.0, 320.0, 500.0, 634.0}) {
    for (double v : {5.0, 240.0, 470.0}) {
      undistorted.push_back({u, v});
      rays.emplace_back((u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy, 1.0);
    }
  }
  const cv::Matx33d k(cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1);
  const cv::Vec<double, 5> d(cam.k1, cam.k2, cam.p1, cam.p2, cam.k3);
  std::vector<cv::Point2d> expected;
  cv::projectPoints(rays, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), k, d, expected);
  for (size_t i = 0; i < undistorted.size(); ++i) {
    const Eigen::Vector2d got = cam.Distort(undistorted[i]);
    EXPECT_NEAR(got.x(), expected[i].x, 1e-6) << i;
    EXPECT_NEAR(got.y(), expected[i].y, 1e-6) << i;
  }
  // In the corners the distortion moves pixels by several pixels, so the check has teeth.
  EXPECT_GT((cam.Distort(undistorted[0]) - undistorted[0]).norm(), 3.0);
}

TEST(PinholeCamera, DistortWithoutDistortionIsIdentity) {
  const PinholeCamera cam;
  const Eigen::Vector2d uv(12.5, 400.25);
  EXPECT_EQ(cam.Distort(uv), uv);
}

}  // namespace
}  // namespace detslam
