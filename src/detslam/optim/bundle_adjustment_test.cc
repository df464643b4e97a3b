#include "detslam/optim/bundle_adjustment.h"

#include <gtest/gtest.h>

#include "detslam/core/check.h"
#include "detslam/core/rng.h"
#include "detslam/geometry/projection.h"

namespace detslam {
namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;

struct Scene {
  BundleProblem truth;
  BundleProblem problem;  // noisy observations, perturbed poses (except the first) and points
};

// ORB-SLAM3's observation model: u_right as noisy as u (disparity_sigma 0).
PinholeCamera URightCamera() {
  PinholeCamera c;
  c.disparity_sigma = 0.0;
  return c;
}

// 10 cameras on a 1.8 m line looking along +z, 200 points 2-4 m away, 1 px noise on (u, v); even
// observations are stereo, with noise as the camera's model says: u_right with 1 px noise of
// its own (disparity_sigma 0), or a disparity u - u_right with disparity_sigma noise.
Scene MakeScene(Rng& rng, const PinholeCamera& camera = URightCamera()) {
  Scene s;
  for (int i = 0; i < 10; ++i) {
    Vector6d world_from_cam;
    world_from_cam << 0.2 * i, 0.02 * i, 0.0, 0.01 * i, -0.02 * i, 0.0;
    s.truth.poses.push_back({i, Rigid3d::Exp(world_from_cam).Inverse(), i == 0});
  }
  for (int j = 0; j < 200; ++j) {
    // One draw per declarator (argument order is unspecified: gcc and clang differ), in the
    // order gcc drew them as arguments (last first), so the scene stays as it was measured.
    const double z = rng.Uniform(2, 4), y = rng.Uniform(-0.8, 0.8), x = rng.Uniform(-0.5, 2.3);
    const Eigen::Vector3d p(x, y, z);
    s.truth.points.push_back({1000 + j, p, false});
  }
  for (size_t i = 0; i < s.truth.poses.size(); ++i) {
    for (size_t j = 0; j < s.truth.points.size(); ++j) {
      const Eigen::Vector3d p_cam = s.truth.poses[i].cam_from_world * s.truth.points[j].p_world;
      const Eigen::Vector3d uvr = ProjectStereo(camera, p_cam);
      if (p_cam.z() <= 0 || !camera.InImage(uvr.head<2>())) continue;
      BundleProblem::Observation o;
      o.pose_index = i;
      o.point_index = j;
      const double nv = rng.Normal(), nu = rng.Normal();
      o.uv = uvr.head<2>() + Eigen::Vector2d(nu, nv);
      if ((i + j) % 2 == 0) {
        o.u_right = camera.disparity_sigma > 0
                        ? o.uv.x() - (camera.bf / p_cam.z() + rng.Normal(0, camera.disparity_sigma))
                        : uvr.z() + rng.Normal();
      }
      s.truth.observations.push_back(o);
    }
  }
  s.problem = s.truth;
  for (size_t i = 1; i < s.problem.poses.size(); ++i) {
    Vector6d d;
    for (int k = 0; k < 3; ++k) d(k) = rng.Normal(0, 0.03);
    for (int k = 3; k < 6; ++k) d(k) = rng.Normal(0, 0.015);
    s.problem.poses[i].cam_from_world = Rigid3d::Exp(d) * s.problem.poses[i].cam_from_world;
  }
  for (BundleProblem::Point& p : s.problem.points) {
    const double dz = rng.Normal(0, 0.05), dy = rng.Normal(0, 0.05), dx = rng.Normal(0, 0.05);
    p.p_world += Eigen::Vector3d(dx, dy, dz);
  }
  return s;
}

double MeanPoseError(const BundleProblem& a, const BundleProblem& b) {
  double sum = 0;
  for (size_t i = 0; i < a.poses.size(); ++i) {
    sum += (a.poses[i].cam_from_world.Inverse().translation() -
            b.poses[i].cam_from_world.Inverse().translation())
               .norm();
  }
  return sum / a.poses.size();
}

double MeanPointError(const BundleProblem& a, const BundleProblem& b) {
  double sum = 0;
  for (size_t j = 0; j < a.points.size(); ++j)
    sum += (a.points[j].p_world - b.points[j].p_world).norm();
  return sum / a.points.size();
}

// Every test runs with both solvers: Ceres's sparse Schur (dense_schur_max_poses 0) and the
// hand-written dense Schur (schur_bundle.h; the default for windows up to 64 free poses).
class BundleAdjustmentTest : public ::testing::TestWithParam<int> {
 protected:
  BundleOptions Options() const {
    BundleOptions o;
    o.dense_schur_max_poses = GetParam();
    return o;
  }
};

INSTANTIATE_TEST_SUITE_P(Solvers, BundleAdjustmentTest, ::testing::Values(0, 64),
                         [](const ::testing::TestParamInfo<int>& info) {
                           return info.param == 0 ? std::string("Ceres") : std::string("DenseSchur");
                         });

TEST_P(BundleAdjustmentTest, MovesPosesAndPointsTowardsTheTruth) {
  Rng rng(1);
  Scene s = MakeScene(rng);
  ASSERT_GT(s.problem.observations.size(), 1000u);
  const double pose_before = MeanPoseError(s.problem, s.truth);
  const double point_before = MeanPointError(s.problem, s.truth);
  const Rigid3d first = s.problem.poses[0].cam_from_world;
  const BundleSummary summary = SolveBundle(URightCamera(), &s.problem, Options());
  ASSERT_TRUE(summary.usable);
  EXPECT_GT(summary.iterations, 0);
  EXPECT_LE(summary.iterations, Options().max_iterations);
  EXPECT_LT(summary.final_cost, 0.1 * summary.initial_cost);
  const double pose_after = MeanPoseError(s.problem, s.truth);
  const double point_after = MeanPointError(s.problem, s.truth);
  EXPECT_LT(pose_after, 0.2 * pose_before) << pose_before << " -> " << pose_after;
  EXPECT_LT(point_after, 0.3 * point_before) << point_before << " -> " << point_after;
  EXPECT_LT(pose_after, 0.01);
  // The fixed pose did not move.
  EXPECT_EQ(s.problem.poses[0].cam_from_world.translation(), first.translation());
  EXPECT_EQ(s.problem.poses[0].cam_from_world.rotation().coeffs(), first.rotation().coeffs());
  // With 1-sigma noise about 5% of the observations fail the 95% gates.
  int flagged = 0;
  for (const bool o : summary.outlier) flagged += o ? 1 : 0;
  EXPECT_LT(flagged, 0.1 * summary.outlier.size());
}

// With the disparity model (the default camera) and data of that model, BA converges, and it
// recovers the points better than the u_right model does on the same data.
TEST_P(BundleAdjustmentTest, DisparityModelWeightsDepthByItsNoise) {
  const PinholeCamera camera;  // disparity_sigma 0.1 px
  ASSERT_GT(camera.disparity_sigma, 0.0);
  Rng rng(5);
  Scene s = MakeScene(rng, camera);
  BundleProblem with_u_right = s.problem;
  const double point_before = MeanPointError(s.problem, s.truth);
  const BundleSummary summary = SolveBundle(camera, &s.problem, Options());
  ASSERT_TRUE(summary.usable);
  EXPECT_LT(MeanPoseError(s.problem, s.truth), 0.01);
  const double point_after = MeanPointError(s.problem, s.truth);
  EXPECT_LT(point_after, 0.3 * point_before) << point_before << " -> " << point_after;
  int flagged = 0;
  for (const bool o : summary.outlier) flagged += o ? 1 : 0;
  EXPECT_LT(flagged, 0.1 * summary.outlier.size());
  ASSERT_TRUE(SolveBundle(URightCamera(), &with_u_right, Options()).usable);
  EXPECT_LT(point_after, MeanPointError(with_u_right, s.truth))
      << point_after << " vs " << MeanPointError(with_u_right, s.truth);
}

TEST_P(BundleAdjustmentTest, FlagsCorruptedObservations) {
  Rng rng(2);
  Scene s = MakeScene(rng);
  std::vector<size_t> corrupted;
  for (size_t k = 7; k < s.problem.observations.size(); k += 97) {
    s.problem.observations[k].uv += Eigen::Vector2d(30.0, -25.0);
    corrupted.push_back(k);
  }
  ASSERT_GE(corrupted.size(), 10u);
  const BundleSummary summary = SolveBundle(URightCamera(), &s.problem, Options());
  ASSERT_TRUE(summary.usable);
  for (const size_t k : corrupted) EXPECT_TRUE(summary.outlier[k]) << k;
  EXPECT_LT(MeanPoseError(s.problem, s.truth), 0.01);
}

TEST_P(BundleAdjustmentTest, AbortFlagStopsBeforeTheFirstStep) {
  Rng rng(3);
  Scene s = MakeScene(rng);
  const BundleProblem before = s.problem;
  const std::atomic<bool> abort(true);
  const BundleSummary summary = SolveBundle(URightCamera(), &s.problem, Options(), &abort);
  EXPECT_EQ(summary.iterations, 0);
  EXPECT_EQ(summary.final_cost, summary.initial_cost);
  for (size_t i = 0; i < before.poses.size(); ++i) {
    const Rigid3d d = s.problem.poses[i].cam_from_world * before.poses[i].cam_from_world.Inverse();
    EXPECT_LT(d.translation().norm() + d.RotationAngle(), 1e-12);
  }
  EXPECT_EQ(MeanPointError(s.problem, before), 0.0);
  // An unset flag does not interfere.
  const std::atomic<bool> go(false);
  EXPECT_GT(SolveBundle(URightCamera(), &s.problem, Options(), &go).iterations, 0);
}

TEST_P(BundleAdjustmentTest, NoFixedPoseIsNotUsableAndBadInputThrows) {
  Rng rng(4);
  Scene s = MakeScene(rng);
  s.problem.poses[0].fixed = false;
  const BundleProblem before = s.problem;
  const BundleSummary summary = SolveBundle(URightCamera(), &s.problem, Options());
  EXPECT_FALSE(summary.usable);
  EXPECT_EQ(MeanPoseError(s.problem, before), 0.0);
  s.problem.poses[0].fixed = true;
  s.problem.observations[0].point_index = s.problem.points.size();
  EXPECT_THROW(SolveBundle(URightCamera(), &s.problem, Options()), InputError);
  BundleOptions bad = Options();
  bad.max_iterations = 0;
  std::string error;
  EXPECT_FALSE(bad.Check(&error));
  EXPECT_THROW(SolveBundle(URightCamera(), &s.problem, bad), InputError);
}

// The two solvers reach the same optimum: the same cost to 1 % and the same poses and points to
// well under the noise, from the same start (one scene, both observation models).
TEST(BundleAdjustmentSolvers, DenseSchurAndCeresAgree) {
  for (const bool disparity : {false, true}) {
    const PinholeCamera camera = disparity ? PinholeCamera() : URightCamera();
    Rng rng(disparity ? 7 : 6);
    const Scene s = MakeScene(rng, camera);
    BundleProblem ceres = s.problem, dense = s.problem;
    BundleOptions ceres_options, dense_options;
    ceres_options.dense_schur_max_poses = 0;
    ceres_options.max_iterations = dense_options.max_iterations = 50;
    const BundleSummary a = SolveBundle(camera, &ceres, ceres_options);
    const BundleSummary b = SolveBundle(camera, &dense, dense_options);
    ASSERT_TRUE(a.usable && b.usable);
    EXPECT_NEAR(b.initial_cost, a.initial_cost, 1e-9 * a.initial_cost);
    EXPECT_NEAR(b.final_cost, a.final_cost, 0.01 * a.final_cost) << "disparity " << disparity;
    EXPECT_LT(MeanPoseError(dense, ceres), 1e-4) << "disparity " << disparity;
    EXPECT_LT(MeanPointError(dense, ceres), 1e-3) << "disparity " << disparity;
    EXPECT_EQ(a.outlier, b.outlier);
  }
}

}  // namespace
}  // namespace detslam
