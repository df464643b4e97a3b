#include "detslam/optim/pose_optimizer.h"

#include <ceres/gradient_checker.h>
#include <ceres/sized_cost_function.h>
#include <gtest/gtest.h>

#include <cmath>

#include "detslam/core/check.h"
#include "detslam/core/rng.h"
#include "detslam/geometry/projection.h"

namespace detslam {
namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;

Rigid3d TruePose() {
  Vector6d twist;
  twist << 0.2, -0.1, 0.3, 0.05, -0.2, 0.1;
  return Rigid3d::Exp(twist);
}

// n observations of points 0.5-6 m in front of the true camera; every second one is stereo;
// octaves 0-7 with inv_sigma2 = 1.2^(-2 octave); pixel noise noise_px (Gaussian).
std::vector<PoseObservation> MakeObservations(const PinholeCamera& camera, int n, double noise_px,
                                              Rng& rng) {
  const Rigid3d world_from_cam = TruePose().Inverse();
  std::vector<PoseObservation> obs;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d p_cam(rng.Uniform(-2, 2), rng.Uniform(-1.5, 1.5), rng.Uniform(0.5, 6));
    const Eigen::Vector3d uvr = ProjectStereo(camera, p_cam);
    const int octave = i % 8;
    const double scale = std::pow(1.2, octave);
    PoseObservation o;
    o.point_world = world_from_cam * p_cam;
    o.uv =
        uvr.head<2>() + Eigen::Vector2d(rng.Normal(0, noise_px), rng.Normal(0, noise_px)) * scale;
    if (i % 2 == 0) o.u_right = o.uv.x() - (uvr.x() - uvr.z());
    o.inv_sigma2 = 1.0 / (scale * scale);
    obs.push_back(o);
  }
  return obs;
}

Rigid3d Perturbed(const Rigid3d& pose) {
  Vector6d delta;
  delta << 0.05, -0.04, 0.06, 0.03, -0.05, 0.04;  // ~8 cm, ~4 deg
  return Rigid3d::Exp(delta) * pose;
}

double TranslationError(const Rigid3d& a, const Rigid3d& b) {
  return (a.Inverse().translation() - b.Inverse().translation()).norm();
}

TEST(PoseOptimizerTest, RecoversPerturbedPoseNoiseFree) {
  const PinholeCamera camera;
  Rng rng(1);
  const std::vector<PoseObservation> obs = MakeObservations(camera, 300, 0.0, rng);
  const PoseOptimizerResult r =
      OptimizePose(camera, Perturbed(TruePose()), obs, PoseOptimizerOptions());
  EXPECT_EQ(r.num_inliers, 300);
  EXPECT_LT((r.cam_from_world * TruePose().Inverse()).RotationAngle(), 1e-6);
  EXPECT_LT(TranslationError(r.cam_from_world, TruePose()), 1e-6);
}

TEST(PoseOptimizerTest, FlagsGrossOutliersAndRecoversPose) {
  const PinholeCamera camera;
  Rng rng(2);
  std::vector<PoseObservation> obs = MakeObservations(camera, 500, 0.0, rng);
  std::vector<bool> truth(obs.size(), true);
  for (size_t i = 0; i < obs.size(); i += 5) {  // 20% gross outliers (40 px and more)
    const Eigen::Vector2d shift(rng.Uniform(40, 80) * (i % 2 ? 1 : -1), rng.Uniform(-80, 80));
    obs[i].uv += shift;
    if (obs[i].u_right >= 0) obs[i].u_right += shift.x();
    truth[i] = false;
  }
  const PoseOptimizerResult r =
      OptimizePose(camera, Perturbed(TruePose()), obs, PoseOptimizerOptions());
  EXPECT_EQ(r.inliers, truth);
  EXPECT_EQ(r.num_inliers, 400);
  EXPECT_LT((r.cam_from_world * TruePose().Inverse()).RotationAngle(), 1e-6);
  EXPECT_LT(TranslationError(r.cam_from_world, TruePose()), 1e-6);
}

TEST(PoseOptimizerTest, NoisyObservationsGiveAccuratePose) {
  const PinholeCamera camera;
  Rng rng(3);
  const std::vector<PoseObservation> obs = MakeObservations(camera, 500, 1.0, rng);
  const PoseOptimizerResult r =
      OptimizePose(camera, Perturbed(TruePose()), obs, PoseOptimizerOptions());
  EXPECT_LT(TranslationError(r.cam_from_world, TruePose()), 0.005);
  EXPECT_LT((r.cam_from_world * TruePose().Inverse()).RotationAngle(), 0.002);
  // With 1-sigma noise about 95% pass the 95% chi2 gates.
  EXPECT_GT(r.num_inliers, 440);
  EXPECT_LT(r.num_inliers, 500);
}

TEST(PoseOptimizerTest, PointsBehindTheCameraAreOutliersAndOptionsAreChecked) {
  const PinholeCamera camera;
  Rng rng(4);
  std::vector<PoseObservation> obs = MakeObservations(camera, 50, 0.0, rng);
  obs[0].point_world = TruePose().Inverse() * Eigen::Vector3d(0.1, 0.1, -2.0);
  const PoseOptimizerResult r = OptimizePose(camera, TruePose(), obs, PoseOptimizerOptions());
  EXPECT_FALSE(r.inliers[0]);
  EXPECT_EQ(r.num_inliers, 49);
  PoseOptimizerOptions bad;
  bad.rounds = 0;
  EXPECT_THROW(OptimizePose(camera, TruePose(), obs, bad), InputError);
}

// Residual ProjectStereo(Exp(delta) * pose * p) with the analytic Jacobian at delta; only exact at
// delta = 0, where it is probed. With wrong_sign the rotation block is negated (negative control).
class PerturbedProjection : public ceres::SizedCostFunction<3, 6> {
 public:
  PerturbedProjection(const PinholeCamera& camera, const Rigid3d& pose, const Eigen::Vector3d& p,
                      bool wrong_sign)
      : camera_(camera), pose_(pose), p_(p), wrong_sign_(wrong_sign) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Vector6d delta(parameters[0]);
    const Eigen::Vector3d p_cam = Rigid3d::Exp(delta) * pose_ * p_;
    Eigen::Map<Eigen::Vector3d>(residuals, 3) = ProjectStereo(camera_, p_cam);
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      Eigen::Matrix<double, 3, 6> j = StereoPoseJacobian(camera_, p_cam);
      if (wrong_sign_) j.rightCols<3>() *= -1.0;
      Eigen::Map<Eigen::Matrix<double, 3, 6, Eigen::RowMajor>> jac(jacobians[0]);
      jac = j;
    }
    return true;
  }

 private:
  PinholeCamera camera_;
  Rigid3d pose_;
  Eigen::Vector3d p_;
  bool wrong_sign_;
};

TEST(PoseOptimizerTest, AnalyticJacobianPassesGradientChecker) {
  const PinholeCamera camera;
  const Eigen::Vector3d p_world(0.4, -0.3, 2.0);
  const double zero[6] = {0, 0, 0, 0, 0, 0};
  const double* params[] = {zero};
  ceres::NumericDiffOptions numeric;
  const std::vector<const ceres::Manifold*>* euclidean = nullptr;
  const PerturbedProjection right(camera, TruePose(), p_world, false);
  const ceres::GradientChecker checker(&right, euclidean, numeric);
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(checker.Probe(params, 1e-6, &results)) << results.error_log;
  // The checker must catch a wrong Jacobian.
  const PerturbedProjection wrong(camera, TruePose(), p_world, true);
  const ceres::GradientChecker wrong_checker(&wrong, euclidean, numeric);
  EXPECT_FALSE(wrong_checker.Probe(params, 1e-6, nullptr));
}

}  // namespace
}  // namespace detslam
