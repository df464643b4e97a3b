#include "detslam/tracking/rolling_shutter.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace detslam {
namespace {

PinholeCamera RollingCamera(double readout) {
  PinholeCamera c;  // 640 x 480, no distortion
  c.rolling_shutter_readout = readout;
  return c;
}

Twist MakeTwist(double vx, double vy, double vz, double wx, double wy, double wz) {
  Twist t;
  t << vx, vy, vz, wx, wy, wz;
  return t;
}

// What a rolling-shutter camera records of a point (world = the camera at the frame's stamp):
// the pixel and depth at the time its row was exposed, found by fixed-point iteration on the row.
struct Observation {
  Eigen::Vector2d uv;
  double depth;
};
Observation ObserveWithRollingShutter(const PinholeCamera& camera, const Twist& xi,
                                      const Eigen::Vector3d& p) {
  double y = camera.Project(p).y();
  Eigen::Vector3d seen = p;
  for (int it = 0; it < 50; ++it) {
    seen = Rigid3d::Exp(RowTimeOffset(camera, y) * xi) * p;  // cam(tau)_from_cam(0)
    y = camera.Project(seen).y();
  }
  return {camera.Project(seen), seen.z()};
}

std::shared_ptr<const FrameFeatures> FeaturesOf(const PinholeCamera& camera,
                                                const std::vector<Observation>& obs,
                                                bool with_depth) {
  std::vector<cv::KeyPoint> kps;
  std::vector<float> depth;
  for (const Observation& o : obs) {
    kps.emplace_back(static_cast<float>(o.uv.x()), static_cast<float>(o.uv.y()), 31.f);
    depth.push_back(with_depth ? static_cast<float>(o.depth) : -1.0f);
  }
  return BuildFrameFeatures(camera, kps, cv::Mat(static_cast<int>(kps.size()), 32, CV_8UC1),
                            depth);
}

std::vector<Eigen::Vector3d> PointsInView() {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 7; ++i) {
    for (int j = 0; j < 5; ++j) {
      const double z = 1.0 + 0.4 * ((i + 2 * j) % 7);
      points.emplace_back((i - 3) * 0.12 * z, (j - 2) * 0.15 * z, z);
    }
  }
  return points;
}

TEST(RollingShutter, RowTimesSpanTheReadoutAroundTheStamp) {
  const PinholeCamera c = RollingCamera(0.03);
  EXPECT_DOUBLE_EQ(RowTimeOffset(c, 0.0), -0.015);
  EXPECT_DOUBLE_EQ(RowTimeOffset(c, c.height - 1), 0.015);
  EXPECT_NEAR(RowTimeOffset(c, (c.height - 1) / 2.0), 0.0, 1e-15);
  EXPECT_DOUBLE_EQ(RowTimeOffset(RollingCamera(0.0), 100.0), 0.0);
}

TEST(RollingShutter, TwistPerSecondReproducesTheMotion) {
  const Rigid3d motion = Rigid3d::Exp(MakeTwist(0.02, -0.01, 0.03, 0.01, 0.02, -0.005));
  const Twist xi = TwistPerSecond(motion, 1.0 / 30.0);
  const Rigid3d back = Rigid3d::Exp(xi / 30.0);
  EXPECT_NEAR((back.translation() - motion.translation()).norm(), 0.0, 1e-12);
  EXPECT_NEAR(back.rotation().angularDistance(motion.rotation()), 0.0, 1e-12);
  EXPECT_TRUE(TwistPerSecond(motion, 0.0).isZero());
}

TEST(RollingShutter, KeypointsWithDepthMoveToWhereTheStampsCameraSawThem) {
  const PinholeCamera c = RollingCamera(0.025);
  // Walking speed and a brisk turn: 0.5 m/s, 60 deg/s.
  const Twist xi = MakeTwist(0.3, -0.1, 0.4, 0.4, -0.9, 0.2);
  std::vector<Observation> obs;
  for (const Eigen::Vector3d& p : PointsInView()) obs.push_back(ObserveWithRollingShutter(c, xi, p));
  const auto raw = FeaturesOf(c, obs, true);
  const auto fixed = CompensateRollingShutter(c, raw, xi);
  ASSERT_NE(fixed, raw);
  const std::vector<Eigen::Vector3d> points = PointsInView();
  double raw_error = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector2d truth = c.Project(points[i]);
    raw_error = std::max(raw_error, (raw->undist[i] - truth).norm());
    // Float keypoints and depths: ~1e-4 px.
    EXPECT_NEAR((fixed->undist[i] - truth).norm(), 0.0, 2e-3) << i;
    EXPECT_NEAR(fixed->depth[i], points[i].z(), 1e-5) << i;
    EXPECT_NEAR(fixed->u_right[i], fixed->undist[i].x() - c.bf / fixed->depth[i], 1e-3);
    // What was detected stays.
    EXPECT_EQ(fixed->keypoints[i].pt, raw->keypoints[i].pt);
  }
  EXPECT_GT(raw_error, 5.0);  // the rolling shutter moved the points by several pixels
  // The area grid follows the moved keypoints.
  const Eigen::Vector2d moved = fixed->undist[0];
  const std::vector<size_t> found = fixed->grid->FeaturesInArea(moved.x(), moved.y(), 0.5);
  EXPECT_NE(std::find(found.begin(), found.end(), 0u), found.end());
}

TEST(RollingShutter, KeypointsWithoutDepthFollowTheRotationExactly) {
  const PinholeCamera c = RollingCamera(0.03);
  const Twist turn = MakeTwist(0, 0, 0, 0.2, 1.0, -0.1);  // rotation only: depth does not matter
  std::vector<Observation> obs;
  for (const Eigen::Vector3d& p : PointsInView()) obs.push_back(ObserveWithRollingShutter(c, turn, p));
  const auto fixed = CompensateRollingShutter(c, FeaturesOf(c, obs, false), turn);
  const std::vector<Eigen::Vector3d> points = PointsInView();
  for (size_t i = 0; i < points.size(); ++i) {
    EXPECT_NEAR((fixed->undist[i] - c.Project(points[i])).norm(), 0.0, 2e-3) << i;
    EXPECT_LT(fixed->depth[i], 0.0f);  // still unknown
    EXPECT_LT(fixed->u_right[i], 0.0f);
  }
}

TEST(RollingShutter, AGlobalShutterOrAStillCameraChangesNothing) {
  const PinholeCamera global = RollingCamera(0.0);
  std::vector<Observation> obs;
  for (const Eigen::Vector3d& p : PointsInView()) obs.push_back({global.Project(p), p.z()});
  const auto raw = FeaturesOf(global, obs, true);
  EXPECT_EQ(CompensateRollingShutter(global, raw, MakeTwist(1, 0, 0, 0, 1, 0)), raw);
  const PinholeCamera rolling = RollingCamera(0.03);
  const auto still = CompensateRollingShutter(rolling, raw, Twist::Zero());
  for (size_t i = 0; i < raw->size(); ++i) {
    EXPECT_NEAR((still->undist[i] - raw->undist[i]).norm(), 0.0, 1e-9);
    EXPECT_FLOAT_EQ(still->depth[i], raw->depth[i]);
  }
}

}  // namespace
}  // namespace detslam
