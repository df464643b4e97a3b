#include "detslam/geometry/projection.h"

#include <gtest/gtest.h>

#include "detslam/geometry/triangulation.h"

namespace detslam {
namespace {

PinholeCamera HandCamera() {
  PinholeCamera camera;
  camera.fx = 500;
  camera.fy = 400;
  camera.cx = 320;
  camera.cy = 240;
  camera.bf = 40;
  return camera;
}

TEST(ProjectionTest, ProjectStereoHandMadeNumbers) {
  // u = 500 * 0.2 / 2 + 320 = 370, v = 400 * -0.1 / 2 + 240 = 220, u_right = 370 - 40 / 2 = 350.
  const Eigen::Vector3d uvr = ProjectStereo(HandCamera(), Eigen::Vector3d(0.2, -0.1, 2.0));
  EXPECT_DOUBLE_EQ(uvr.x(), 370.0);
  EXPECT_DOUBLE_EQ(uvr.y(), 220.0);
  EXPECT_DOUBLE_EQ(uvr.z(), 350.0);
}

TEST(ProjectionTest, WhitenedStereoResidualHandMadeNumbers) {
  // Point as above (u 370, v 220, u_right 350, disparity bf / z = 20); observed (371, 218) with
  // u_right 349.5, i.e. disparity 21.5; sqrt_info 0.5.
  PinholeCamera camera = HandCamera();
  const Eigen::Vector3d p(0.2, -0.1, 2.0);
  const Eigen::Vector2d uv(371.0, 218.0);
  camera.disparity_sigma = 0.5;
  Eigen::Vector3d r = WhitenedStereoResidual(camera, p, uv, 349.5, 0.5);
  EXPECT_DOUBLE_EQ(r.x(), 0.5 * (370.0 - 371.0));
  EXPECT_DOUBLE_EQ(r.y(), 0.5 * (220.0 - 218.0));
  EXPECT_DOUBLE_EQ(r.z(), (20.0 - 21.5) / 0.5);
  camera.disparity_sigma = 0.0;  // ORB-SLAM3: u_right error with the keypoint's sigma
  r = WhitenedStereoResidual(camera, p, uv, 349.5, 0.5);
  EXPECT_DOUBLE_EQ(r.z(), 0.5 * (350.0 - 349.5));
}

TEST(ProjectionTest, PixelToNormalizedInvertsProjection) {
  const Eigen::Vector2d xn = PixelToNormalized(HandCamera(), Eigen::Vector2d(370.0, 220.0));
  EXPECT_DOUBLE_EQ(xn.x(), 0.1);
  EXPECT_DOUBLE_EQ(xn.y(), -0.05);
}

TEST(TriangulationTest, HandMadeTwoViewPoint) {
  // Camera 2 sits 1 m to the right of camera 1 (same orientation).
  const Rigid3d cam1_from_world;
  const Rigid3d cam2_from_world(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-1.0, 0.0, 0.0));
  Eigen::Vector3d p;
  ASSERT_TRUE(TriangulateLinear(cam1_from_world, cam2_from_world, Eigen::Vector2d(0.25, 0.125),
                                Eigen::Vector2d(-0.25, 0.125), &p));
  EXPECT_NEAR(p.x(), 0.5, 1e-12);
  EXPECT_NEAR(p.y(), 0.25, 1e-12);
  EXPECT_NEAR(p.z(), 2.0, 1e-12);
}

TEST(TriangulationTest, RotatedSecondCamera) {
  const Rigid3d cam1_from_world;
  // Camera 2 at (3, 0, 2) looking along world -x (rotated by -90 deg about y).
  const Eigen::Quaterniond r(Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitY()));
  const Rigid3d world_from_cam2(r, Eigen::Vector3d(3.0, 0.0, 2.0));
  const Rigid3d cam2_from_world = world_from_cam2.Inverse();
  const Eigen::Vector3d truth(0.3, -0.2, 2.5);
  const Eigen::Vector3d c1 = cam1_from_world * truth, c2 = cam2_from_world * truth;
  ASSERT_GT(c2.z(), 0.0);
  Eigen::Vector3d p;
  ASSERT_TRUE(
      TriangulateLinear(cam1_from_world, cam2_from_world, c1.hnormalized(), c2.hnormalized(), &p));
  EXPECT_LT((p - truth).norm(), 1e-10);
}

TEST(TriangulationTest, RejectsPointBehindCamerasAndParallelRays) {
  const Rigid3d cam1_from_world;
  const Rigid3d cam2_from_world(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-1.0, 0.0, 0.0));
  const Eigen::Vector3d untouched(7.0, 7.0, 7.0);
  Eigen::Vector3d p = untouched;
  // The rays meet at (0.5, 0, -2): behind both cameras.
  EXPECT_FALSE(TriangulateLinear(cam1_from_world, cam2_from_world, Eigen::Vector2d(-0.25, 0.0),
                                 Eigen::Vector2d(0.25, 0.0), &p));
  // Identical directions from two centres: the point is at infinity.
  EXPECT_FALSE(TriangulateLinear(cam1_from_world, cam2_from_world, Eigen::Vector2d(0.1, 0.0),
                                 Eigen::Vector2d(0.1, 0.0), &p));
  EXPECT_EQ(p, untouched);
}

TEST(TriangulationTest, CosParallaxHandMade) {
  const Rigid3d cam1_from_world;
  const Rigid3d cam2_from_world(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-1.0, 0.0, 0.0));
  // Centres (0,0,0) and (1,0,0), point (0.5,0,0.5): the rays meet at a right angle.
  EXPECT_NEAR(CosParallax(cam1_from_world, cam2_from_world, Eigen::Vector3d(0.5, 0, 0.5)), 0.0,
              1e-15);
  // Point (0.5, 0, 0.5*sqrt(3)): rays at 60 degrees.
  EXPECT_NEAR(
      CosParallax(cam1_from_world, cam2_from_world, Eigen::Vector3d(0.5, 0, 0.5 * std::sqrt(3.0))),
      0.5, 1e-12);
  EXPECT_NEAR(CosParallaxRays(cam1_from_world, cam2_from_world, Eigen::Vector2d(1.0, 0.0),
                              Eigen::Vector2d(-1.0, 0.0)),
              0.0, 1e-15);
  EXPECT_NEAR(CosParallaxRays(cam1_from_world, cam2_from_world, Eigen::Vector2d(0.2, 0.1),
                              Eigen::Vector2d(0.2, 0.1)),
              1.0, 1e-15);
}

}  // namespace
}  // namespace detslam
