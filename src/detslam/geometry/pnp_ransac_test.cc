#include "detslam/geometry/pnp_ransac.h"

#include <gtest/gtest.h>

#include "detslam/core/check.h"

namespace detslam {
namespace {

struct PnpScene {
  Rigid3d cam_from_world;
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;
  std::vector<bool> is_inlier;
};

// n correspondences; a fraction outlier_ratio gets a random pixel at least 20 px from the truth.
PnpScene MakePnpScene(const PinholeCamera& camera, int n, double outlier_ratio, Rng& rng) {
  PnpScene s;
  Eigen::Matrix<double, 6, 1> twist;
  twist << 0.3, -0.2, 0.5, 0.1, -0.25, 0.05;
  s.cam_from_world = Rigid3d::Exp(twist);
  const Rigid3d world_from_cam = s.cam_from_world.Inverse();
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d p_cam(rng.Uniform(-1.5, 1.5), rng.Uniform(-1.0, 1.0),
                                rng.Uniform(1.0, 5.0));
    s.points.push_back(world_from_cam * p_cam);
    Eigen::Vector2d uv = camera.Project(p_cam);
    const bool outlier = i < static_cast<int>(outlier_ratio * n);
    if (outlier) {
      Eigen::Vector2d wrong;
      do {
        wrong = {rng.Uniform(0, camera.width), rng.Uniform(0, camera.height)};
      } while ((wrong - uv).norm() < 20.0);
      uv = wrong;
    }
    s.pixels.push_back(uv);
    s.is_inlier.push_back(!outlier);
  }
  return s;
}

TEST(PnpRansacTest, RecoversExactPoseWithFortyPercentOutliers) {
  const PinholeCamera camera;
  Rng scene_rng(1);
  const PnpScene s = MakePnpScene(camera, 200, 0.4, scene_rng);
  Rng rng(42);
  const PnpResult r = SolvePnpRansac(camera, s.points, s.pixels, {}, RansacOptions(), rng);
  ASSERT_TRUE(r.success);
  EXPECT_EQ(r.num_inliers, 120);
  EXPECT_EQ(r.inliers, s.is_inlier);
  const Rigid3d err = r.cam_from_world * s.cam_from_world.Inverse();
  EXPECT_LT(err.RotationAngle(), 1e-6);
  EXPECT_LT(err.translation().norm(), 1e-6);
  EXPECT_GT(r.iterations, 0);
  EXPECT_LE(r.iterations, RansacOptions().max_iterations);
}

TEST(PnpRansacTest, SameSeedGivesIdenticalResult) {
  const PinholeCamera camera;
  Rng scene_rng(2);
  const PnpScene s = MakePnpScene(camera, 150, 0.4, scene_rng);
  Rng rng1(7), rng2(7);
  const PnpResult a = SolvePnpRansac(camera, s.points, s.pixels, {}, RansacOptions(), rng1);
  const PnpResult b = SolvePnpRansac(camera, s.points, s.pixels, {}, RansacOptions(), rng2);
  EXPECT_EQ(a.success, b.success);
  EXPECT_EQ(a.iterations, b.iterations);
  EXPECT_EQ(a.inliers, b.inliers);
  EXPECT_EQ(a.cam_from_world.rotation().coeffs(), b.cam_from_world.rotation().coeffs());
  EXPECT_EQ(a.cam_from_world.translation(), b.cam_from_world.translation());
}

TEST(PnpRansacTest, FailsOnPureNoise) {
  const PinholeCamera camera;
  Rng rng(3);
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;
  for (int i = 0; i < 100; ++i) {
    points.emplace_back(rng.Uniform(-2, 2), rng.Uniform(-2, 2), rng.Uniform(1, 6));
    pixels.emplace_back(rng.Uniform(0, camera.width), rng.Uniform(0, camera.height));
  }
  const PnpResult r = SolvePnpRansac(camera, points, pixels, {}, RansacOptions(), rng);
  EXPECT_FALSE(r.success);
  EXPECT_LT(r.num_inliers, RansacOptions().min_inliers);
  EXPECT_EQ(r.iterations, RansacOptions().max_iterations);
}

TEST(PnpRansacTest, Sigma2ScalesTheInlierTest) {
  const PinholeCamera camera;
  Rng scene_rng(4);
  PnpScene s = MakePnpScene(camera, 60, 0.0, scene_rng);
  // Move the last 10 observations by 5 px: chi2 = 25 / sigma2.
  for (int i = 50; i < 60; ++i) s.pixels[i].x() += 5.0;
  std::vector<double> sigma2(60, 1.0);
  Rng rng1(5);
  const PnpResult tight = SolvePnpRansac(camera, s.points, s.pixels, sigma2, RansacOptions(), rng1);
  ASSERT_TRUE(tight.success);
  EXPECT_EQ(tight.num_inliers, 50);
  for (int i = 50; i < 60; ++i) sigma2[i] = 16.0;  // 25 / 16 < 5.991
  Rng rng2(5);
  const PnpResult loose = SolvePnpRansac(camera, s.points, s.pixels, sigma2, RansacOptions(), rng2);
  ASSERT_TRUE(loose.success);
  EXPECT_EQ(loose.num_inliers, 60);
}

TEST(PnpRansacTest, TooFewPointsAndBadInput) {
  const PinholeCamera camera;
  Rng rng(6);
  const PnpScene s = MakePnpScene(camera, 8, 0.0, rng);
  EXPECT_FALSE(SolvePnpRansac(camera, s.points, s.pixels, {}, RansacOptions(), rng).success);
  std::vector<Eigen::Vector2d> short_pixels(s.pixels.begin(), s.pixels.end() - 1);
  EXPECT_THROW(SolvePnpRansac(camera, s.points, short_pixels, {}, RansacOptions(), rng),
               InputError);
  RansacOptions bad;
  bad.probability = 1.5;
  std::string error;
  EXPECT_FALSE(bad.Check(&error));
  EXPECT_NE(error.find("probability"), std::string::npos);
  EXPECT_THROW(SolvePnpRansac(camera, s.points, s.pixels, {}, bad, rng), InputError);
}

TEST(PnpRansacTest, AdaptiveIterations) {
  // 50% inliers, 4-point samples, p = 0.99: log(0.01) / log(1 - 1/16) = 71.35 -> 72.
  EXPECT_EQ(AdaptiveIterations(0.5, 4, 0.99, 300), 72);
  EXPECT_EQ(AdaptiveIterations(0.1, 4, 0.99, 300), 300);
  EXPECT_EQ(AdaptiveIterations(1.0, 4, 0.99, 300), 1);
  EXPECT_EQ(AdaptiveIterations(0.0, 4, 0.99, 300), 300);
}

}  // namespace
}  // namespace detslam
