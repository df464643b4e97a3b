#include "detslam/geometry/rigid_ransac.h"

#include <gtest/gtest.h>

#include "detslam/core/check.h"

namespace detslam {
namespace {

struct RigidScene {
  Rigid3d b_from_a;
  std::vector<Eigen::Vector3d> a, b;
  std::vector<bool> is_inlier;
};

RigidScene MakeRigidScene(int n, double outlier_ratio, Rng& rng) {
  RigidScene s;
  Eigen::Matrix<double, 6, 1> twist;
  twist << 1.0, -0.5, 0.2, 0.4, 0.3, -0.6;
  s.b_from_a = Rigid3d::Exp(twist);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d a(rng.Uniform(-3, 3), rng.Uniform(-3, 3), rng.Uniform(0, 6));
    Eigen::Vector3d b = s.b_from_a * a;
    const bool outlier = i % 5 < 2 && outlier_ratio > 0;  // 40% of the pairs
    if (outlier)
      b += Eigen::Vector3d(rng.Uniform(0.5, 2), rng.Uniform(-2, -0.5), rng.Uniform(0.5, 2));
    s.a.push_back(a);
    s.b.push_back(b);
    s.is_inlier.push_back(!outlier);
  }
  return s;
}

TEST(RigidRansacTest, KabschHandMade) {
  // b = rotation of 90 deg about z, then + (1, 2, 3).
  const std::vector<Eigen::Vector3d> a = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const std::vector<Eigen::Vector3d> b = {{1, 2, 3}, {1, 3, 3}, {0, 2, 3}, {1, 2, 4}};
  Rigid3d b_from_a;
  ASSERT_TRUE(FitRigidKabsch(a, b, {0, 1, 2, 3}, &b_from_a));
  EXPECT_NEAR(b_from_a.RotationAngle(), M_PI / 2, 1e-12);
  EXPECT_LT((b_from_a.translation() - Eigen::Vector3d(1, 2, 3)).norm(), 1e-12);
  EXPECT_LT((b_from_a * Eigen::Vector3d(1, 1, 1) - Eigen::Vector3d(0, 3, 4)).norm(), 1e-12);
  // Collinear points leave the rotation about their line undetermined.
  const std::vector<Eigen::Vector3d> line = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  EXPECT_FALSE(FitRigidKabsch(line, line, {0, 1, 2}, &b_from_a));
}

TEST(RigidRansacTest, RecoversExactTransformWithFortyPercentOutliers) {
  Rng scene_rng(11);
  const RigidScene s = MakeRigidScene(100, 0.4, scene_rng);
  Rng rng(12);
  const RigidRansacResult r = EstimateRigidRansac(s.a, s.b, 0.05, RansacOptions(), rng);
  ASSERT_TRUE(r.success);
  EXPECT_EQ(r.num_inliers, 60);
  EXPECT_EQ(r.inliers, s.is_inlier);
  const Rigid3d err = r.b_from_a * s.b_from_a.Inverse();
  EXPECT_LT(err.RotationAngle(), 1e-9);
  EXPECT_LT(err.translation().norm(), 1e-9);
}

TEST(RigidRansacTest, SameSeedGivesIdenticalResult) {
  Rng scene_rng(13);
  const RigidScene s = MakeRigidScene(80, 0.4, scene_rng);
  Rng rng1(99), rng2(99);
  const RigidRansacResult a = EstimateRigidRansac(s.a, s.b, 0.05, RansacOptions(), rng1);
  const RigidRansacResult b = EstimateRigidRansac(s.a, s.b, 0.05, RansacOptions(), rng2);
  EXPECT_EQ(a.iterations, b.iterations);
  EXPECT_EQ(a.inliers, b.inliers);
  EXPECT_EQ(a.b_from_a.rotation().coeffs(), b.b_from_a.rotation().coeffs());
  EXPECT_EQ(a.b_from_a.translation(), b.b_from_a.translation());
}

TEST(RigidRansacTest, FailsOnPureNoise) {
  Rng rng(14);
  std::vector<Eigen::Vector3d> a, b;
  for (int i = 0; i < 100; ++i) {
    a.emplace_back(rng.Uniform(-5, 5), rng.Uniform(-5, 5), rng.Uniform(-5, 5));
    b.emplace_back(rng.Uniform(-5, 5), rng.Uniform(-5, 5), rng.Uniform(-5, 5));
  }
  const RigidRansacResult r = EstimateRigidRansac(a, b, 0.05, RansacOptions(), rng);
  EXPECT_FALSE(r.success);
  EXPECT_LT(r.num_inliers, RansacOptions().min_inliers);
  EXPECT_THROW(EstimateRigidRansac(a, {}, 0.05, RansacOptions(), rng), InputError);
  EXPECT_THROW(EstimateRigidRansac(a, b, -1.0, RansacOptions(), rng), InputError);
}

}  // namespace
}  // namespace detslam
