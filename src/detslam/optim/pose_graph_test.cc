#include "detslam/optim/pose_graph.h"

#include <ceres/gradient_checker.h>
#include <ceres/manifold.h>
#include <gtest/gtest.h>

#include <memory>

#include "detslam/core/check.h"
#include "detslam/core/rng.h"

namespace detslam {
namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;

Rigid3d YawPose(double yaw_deg, const Eigen::Vector3d& t) {
  return Rigid3d(
      Eigen::Quaterniond(Eigen::AngleAxisd(yaw_deg * M_PI / 180, Eigen::Vector3d::UnitZ())), t);
}

TEST(PoseGraphTest, RelativePoseResidualHandMade) {
  // Node i at the origin; node j: cam_from_world = yaw 90 deg, so cam_i_from_cam_j = yaw -90 deg.
  const double qi[4] = {0, 0, 0, 1}, ti[3] = {0, 0, 0};
  const double qj[4] = {0, 0, std::sqrt(0.5), std::sqrt(0.5)}, tj[3] = {0, 0, -1};
  const double* params[] = {qi, ti, qj, tj};
  // Estimate: cam_i_from_cam_j = (yaw -90, -yaw(-90) * (0,0,-1)) = (yaw -90, (0, 0, 1)).
  std::unique_ptr<ceres::CostFunction> exact(
      RelativePoseCost::Create(YawPose(-90, Eigen::Vector3d(0, 0, 1)), 1.0));
  double r[6];
  ASSERT_TRUE(exact->Evaluate(params, r, nullptr));
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(r[k], 0.0, 1e-12) << k;
  // Measured identity, sqrt weight 4: translation error (0,0,1), rotation error yaw -90
  // -> 2 * sin(-45 deg) on z.
  std::unique_ptr<ceres::CostFunction> off(RelativePoseCost::Create(Rigid3d(), 4.0));
  ASSERT_TRUE(off->Evaluate(params, r, nullptr));
  EXPECT_NEAR(r[0], 0.0, 1e-12);
  EXPECT_NEAR(r[1], 0.0, 1e-12);
  EXPECT_NEAR(r[2], 4.0 * 1.0, 1e-12);
  EXPECT_NEAR(r[5], 4.0 * 2.0 * -std::sqrt(0.5), 1e-12);
}

TEST(PoseGraphTest, GradientCheckerAccepts) {
  const Rigid3d measured = Rigid3d::Exp((Vector6d() << 0.3, -0.2, 0.1, 0.2, 0.1, -0.3).finished());
  std::unique_ptr<ceres::CostFunction> cost(RelativePoseCost::Create(measured, 1.5));
  const Rigid3d a = Rigid3d::Exp((Vector6d() << 1, 2, 3, 0.4, -0.2, 0.5).finished());
  const Rigid3d b = Rigid3d::Exp((Vector6d() << -1, 0.5, 2, -0.3, 0.6, 0.1).finished());
  const double qi[4] = {a.rotation().x(), a.rotation().y(), a.rotation().z(), a.rotation().w()};
  const double qj[4] = {b.rotation().x(), b.rotation().y(), b.rotation().z(), b.rotation().w()};
  const double* params[] = {qi, a.translation().data(), qj, b.translation().data()};
  ceres::EigenQuaternionManifold quaternion;
  const std::vector<const ceres::Manifold*> manifolds = {&quaternion, nullptr, &quaternion,
                                                         nullptr};
  const ceres::GradientChecker checker(cost.get(), &manifolds, ceres::NumericDiffOptions());
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(checker.Probe(params, 1e-7, &results)) << results.error_log;
}

TEST(PoseGraphTest, LoopClosureReducesDrift) {
  // 20 poses on a circle; odometry with a systematic drift; one exact loop edge 19 -> 0.
  const int n = 20;
  std::vector<Rigid3d> truth;
  for (int k = 0; k < n; ++k) {
    const double a = 2 * M_PI * k / n;
    truth.push_back(
        YawPose(a * 180 / M_PI, Eigen::Vector3d(2 * std::cos(a), 2 * std::sin(a), 0)).Inverse());
  }
  Rng rng(5);
  PoseGraphProblem problem;
  problem.nodes.push_back({0, truth[0], false});
  for (int k = 0; k + 1 < n; ++k) {
    const Rigid3d rel = truth[k] * truth[k + 1].Inverse();
    Vector6d drift;
    drift << 0.02 + rng.Normal(0, 0.002), rng.Normal(0, 0.002), 0.01, 0.0, 0.0, 0.02;
    const Rigid3d measured = Rigid3d::Exp(drift) * rel;
    problem.edges.push_back({static_cast<size_t>(k), static_cast<size_t>(k + 1), measured, 1.0});
    // Dead reckoning: cam_{k+1}_from_world = measured^-1 * cam_k_from_world.
    problem.nodes.push_back({k + 1, measured.Inverse() * problem.nodes[k].cam_from_world, false});
  }
  problem.edges.push_back({static_cast<size_t>(n - 1), 0, truth[n - 1] * truth[0].Inverse(), 1.0});
  auto mean_error = [&]() {
    double sum = 0;
    for (int k = 0; k < n; ++k) {
      sum += (problem.nodes[k].cam_from_world.Inverse().translation() -
              truth[k].Inverse().translation())
                 .norm();
    }
    return sum / n;
  };
  const double before = mean_error();
  const PoseGraphSummary summary = SolvePoseGraph(&problem, PoseGraphOptions());
  const double after = mean_error();
  ASSERT_TRUE(summary.usable);
  EXPECT_GT(before, 0.2);
  EXPECT_LT(after, 0.25 * before) << before << " -> " << after;
  EXPECT_LT(summary.final_cost, 0.1 * summary.initial_cost);
  // The first node is the gauge: untouched.
  EXPECT_EQ(problem.nodes[0].cam_from_world.translation(), truth[0].translation());
  problem.edges[0].weight = 0.0;
  EXPECT_THROW(SolvePoseGraph(&problem, PoseGraphOptions()), InputError);
}

}  // namespace
}  // namespace detslam
