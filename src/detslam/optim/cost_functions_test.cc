#include "detslam/optim/cost_functions.h"

#include <ceres/gradient_checker.h>
#include <ceres/manifold.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>

namespace detslam {
namespace {

StereoIntrinsics HandIntrinsics() { return {500.0, 400.0, 320.0, 240.0, 40.0}; }

// cam_from_world: 90 deg about z, then + (0.1, 0, 1).
// World (-0.1, -0.2, 1) -> camera (0.3, -0.1, 2) -> u = 500 * 0.15 + 320 = 395,
// v = 400 * -0.05 + 240 = 220, u_right = 395 - 40 / 2 = 375.
const double kQ[4] = {0.0, 0.0, std::sqrt(0.5), std::sqrt(0.5)};
const double kT[3] = {0.1, 0.0, 1.0};
const double kP[3] = {-0.1, -0.2, 1.0};

TEST(CostFunctionsTest, StereoResidualHandMade) {
  std::unique_ptr<ceres::CostFunction> cost(
      StereoReprojectionCost::Create(HandIntrinsics(), Eigen::Vector3d(394, 221, 372), 2.0));
  const double* params[] = {kQ, kT, kP};
  double r[3];
  ASSERT_TRUE(cost->Evaluate(params, r, nullptr));
  EXPECT_NEAR(r[0], 2.0 * (395 - 394), 1e-12);
  EXPECT_NEAR(r[1], 2.0 * (220 - 221), 1e-12);
  EXPECT_NEAR(r[2], 2.0 * (375 - 372), 1e-12);
}

TEST(CostFunctionsTest, MonoResidualHandMade) {
  std::unique_ptr<ceres::CostFunction> cost(
      MonoReprojectionCost::Create(HandIntrinsics(), Eigen::Vector2d(390, 230), 0.5));
  const double* params[] = {kQ, kT, kP};
  double r[3] = {1.0, 1.0, 1.0};
  ASSERT_TRUE(cost->Evaluate(params, r, nullptr));
  // Three rows like the stereo residual (one block shape for Ceres's Schur eliminator); the third
  // is exactly 0.
  EXPECT_EQ(cost->num_residuals(), 3);
  EXPECT_NEAR(r[0], 0.5 * 5.0, 1e-12);
  EXPECT_NEAR(r[1], 0.5 * -10.0, 1e-12);
  EXPECT_EQ(r[2], 0.0);
}

// Probes the Jacobians (in the quaternion's tangent space) against numeric differentiation at a
// generic, non-symmetric configuration. `exact_zeros`: the residual has Jacobian entries that are
// exactly zero (where relative errors cannot compare); then every entry must match to 1e-7
// absolute or relative, whichever is larger.
void ExpectGradientsMatch(const ceres::CostFunction& cost, int num_blocks,
                          bool exact_zeros = false) {
  const Eigen::Quaterniond rot =
      Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d(0.3, -0.5, 0.8).normalized()));
  const double q[4] = {rot.x(), rot.y(), rot.z(), rot.w()};
  const double t[3] = {0.2, -0.1, 0.7};
  const double p[3] = {0.5, 0.3, 2.5};
  const double* params[] = {q, t, p};
  ceres::EigenQuaternionManifold quaternion;
  std::vector<const ceres::Manifold*> manifolds(num_blocks, nullptr);
  manifolds[0] = &quaternion;
  ceres::NumericDiffOptions numeric;
  const ceres::GradientChecker checker(&cost, &manifolds, numeric);
  ceres::GradientChecker::ProbeResults results;
  const bool ok = checker.Probe(params, 1e-7, &results);
  if (!exact_zeros) {
    EXPECT_TRUE(ok) << results.error_log;
    EXPECT_LT(results.maximum_relative_error, 1e-7);
    return;
  }
  ASSERT_EQ(results.local_jacobians.size(), static_cast<size_t>(num_blocks));
  for (int b = 0; b < num_blocks; ++b) {
    const auto& user = results.local_jacobians[b];
    const auto& numeric = results.local_numeric_jacobians[b];
    for (int i = 0; i < user.rows(); ++i) {
      for (int j = 0; j < user.cols(); ++j) {
        EXPECT_NEAR(user(i, j), numeric(i, j), 1e-7 * std::max(1.0, std::abs(numeric(i, j))))
            << "block " << b << " (" << i << ", " << j << ")";
      }
    }
  }
}

TEST(CostFunctionsTest, GradientCheckerAcceptsAllResiduals) {
  std::unique_ptr<ceres::CostFunction> c1(
      StereoReprojectionCost::Create(HandIntrinsics(), Eigen::Vector3d(400, 250, 390), 1.7));
  std::unique_ptr<ceres::CostFunction> c2(
      MonoReprojectionCost::Create(HandIntrinsics(), Eigen::Vector2d(400, 250), 0.8));
  ExpectGradientsMatch(*c1, 3);
  ExpectGradientsMatch(*c2, 3);
}

// Disparity model: the third residual is (bf / z - (u_obs - u_right_obs)) / disparity_sigma,
// independent of sqrt_info: (40 / 2 - (394 - 372)) / 0.25 = -8.
TEST(CostFunctionsTest, StereoDisparityResidualHandMade) {
  StereoIntrinsics k = HandIntrinsics();
  k.disparity_sigma = 0.25;
  std::unique_ptr<ceres::CostFunction> cost(
      StereoReprojectionCost::Create(k, Eigen::Vector3d(394, 221, 372), 2.0));
  const double* params[] = {kQ, kT, kP};
  double r[3];
  ASSERT_TRUE(cost->Evaluate(params, r, nullptr));
  EXPECT_NEAR(r[0], 2.0 * (395 - 394), 1e-12);
  EXPECT_NEAR(r[1], 2.0 * (220 - 221), 1e-12);
  EXPECT_NEAR(r[2], (20.0 - 22.0) / 0.25, 1e-12);
  // The depth does not change under a rotation about the camera's optical axis: an exact zero.
  ExpectGradientsMatch(*cost, 3, /*exact_zeros=*/true);
}

}  // namespace
}  // namespace detslam
