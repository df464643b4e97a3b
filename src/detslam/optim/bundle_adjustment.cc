#include "detslam/optim/bundle_adjustment.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>

#include "detslam/core/check.h"
#include "detslam/geometry/projection.h"
#include "detslam/optim/cost_functions.h"
#include "detslam/optim/schur_bundle.h"

namespace detslam {
namespace {

class AbortCallback : public ceres::IterationCallback {
 public:
  explicit AbortCallback(const std::atomic<bool>* flag) : flag_(flag) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary&) override {
    return flag_->load() ? ceres::SOLVER_TERMINATE_SUCCESSFULLY : ceres::SOLVER_CONTINUE;
  }

 private:
  const std::atomic<bool>* flag_;
};

void ChooseLinearSolver(ceres::Solver::Options* options) {
  if (ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::SUITE_SPARSE)) {
    options->linear_solver_type = ceres::SPARSE_SCHUR;
    options->sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
  } else if (ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::EIGEN_SPARSE)) {
    options->linear_solver_type = ceres::SPARSE_SCHUR;
    options->sparse_linear_algebra_library_type = ceres::EIGEN_SPARSE;
  } else {
    options->linear_solver_type = ceres::DENSE_SCHUR;
  }
}

// Per observation: chi2 above its threshold or the point not in front of the camera.
std::vector<bool> ClassifyObservations(const PinholeCamera& camera, const BundleProblem& problem,
                                       const BundleOptions& options) {
  std::vector<bool> outlier(problem.observations.size(), false);
  for (size_t i = 0; i < problem.observations.size(); ++i) {
    const BundleProblem::Observation& o = problem.observations[i];
    const Eigen::Vector3d p_cam =
        problem.poses[o.pose_index].cam_from_world * problem.points[o.point_index].p_world;
    if (p_cam.z() <= 0.0) {
      outlier[i] = true;
      continue;
    }
    const Eigen::Vector3d r =
        WhitenedStereoResidual(camera, p_cam, o.uv, o.u_right, std::sqrt(o.inv_sigma2));
    outlier[i] = o.u_right >= 0.0 ? r.squaredNorm() > options.chi2_stereo
                                  : r.head<2>().squaredNorm() > options.chi2_mono;
  }
  return outlier;
}

BundleSummary SolveWithCeres(const PinholeCamera& camera, BundleProblem* problem,
                             const BundleOptions& options, const std::atomic<bool>* abort_flag);

}  // namespace

bool BundleOptions::Check(std::string* error) const {
  std::ostringstream os;
  if (max_iterations <= 0) os << "max_iterations must be positive; ";
  if (!(chi2_mono > 0.0) || !(chi2_stereo > 0.0)) os << "chi2 thresholds must be positive; ";
  if (num_threads <= 0) os << "num_threads must be positive; ";
  if (dense_schur_max_poses < 0) os << "dense_schur_max_poses must not be negative; ";
  if (error != nullptr) *error = os.str();
  return os.str().empty();
}

BundleSummary SolveBundle(const PinholeCamera& camera, BundleProblem* problem,
                          const BundleOptions& options, const std::atomic<bool>* abort_flag) {
  DETSLAM_CHECK(problem != nullptr);
  std::string error;
  if (!options.Check(&error)) throw InputError("SolveBundle options: " + error);
  for (const BundleProblem::Observation& o : problem->observations) {
    if (o.pose_index >= problem->poses.size() || o.point_index >= problem->points.size()) {
      throw InputError("SolveBundle: observation refers to a missing pose or point");
    }
    if (!(o.inv_sigma2 > 0.0)) throw InputError("SolveBundle: inv_sigma2 must be positive");
  }
  BundleSummary summary;
  summary.outlier.assign(problem->observations.size(), false);
  size_t free_poses = 0;
  for (const BundleProblem::Pose& p : problem->poses) free_poses += p.fixed ? 0 : 1;
  if (free_poses == problem->poses.size()) return summary;  // no fixed pose: gauge free
  if (free_poses <= static_cast<size_t>(options.dense_schur_max_poses)) {
    summary = SolveBundleDenseSchur(camera, problem, options, abort_flag);
    summary.outlier = ClassifyObservations(camera, *problem, options);
    return summary;
  }
  return SolveWithCeres(camera, problem, options, abort_flag);
}

namespace {

BundleSummary SolveWithCeres(const PinholeCamera& camera, BundleProblem* problem,
                             const BundleOptions& options, const std::atomic<bool>* abort_flag) {
  BundleSummary summary;
  // Parameter storage: quaternion [x, y, z, w] and translation per pose, 3 values per point.
  const size_t num_poses = problem->poses.size();
  std::vector<double> q(4 * num_poses), t(3 * num_poses), x(3 * problem->points.size());
  for (size_t i = 0; i < num_poses; ++i) {
    Eigen::Map<Eigen::Vector4d> qi(&q[4 * i]);
    Eigen::Map<Eigen::Vector3d> ti(&t[3 * i]);
    qi = problem->poses[i].cam_from_world.rotation().coeffs();
    ti = problem->poses[i].cam_from_world.translation();
  }
  for (size_t j = 0; j < problem->points.size(); ++j) {
    Eigen::Map<Eigen::Vector3d> xj(&x[3 * j]);
    xj = problem->points[j].p_world;
  }

  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem ceres_problem(problem_options);
  ceres::EigenQuaternionManifold quaternion_manifold;
  ceres::HuberLoss huber_mono(std::sqrt(options.chi2_mono));
  ceres::HuberLoss huber_stereo(std::sqrt(options.chi2_stereo));
  const StereoIntrinsics k = StereoIntrinsics::From(camera);
  std::vector<bool> pose_added(num_poses, false), point_added(problem->points.size(), false);
  for (const BundleProblem::Observation& o : problem->observations) {
    double* qi = &q[4 * o.pose_index];
    double* ti = &t[3 * o.pose_index];
    double* xj = &x[3 * o.point_index];
    const double sqrt_info = std::sqrt(o.inv_sigma2);
    if (o.u_right >= 0.0) {
      ceres_problem.AddResidualBlock(
          StereoReprojectionCost::Create(k, Eigen::Vector3d(o.uv.x(), o.uv.y(), o.u_right),
                                         sqrt_info),
          &huber_stereo, qi, ti, xj);
    } else {
      ceres_problem.AddResidualBlock(MonoReprojectionCost::Create(k, o.uv, sqrt_info), &huber_mono,
                                     qi, ti, xj);
    }
    if (!pose_added[o.pose_index]) {
      pose_added[o.pose_index] = true;
      ceres_problem.SetManifold(qi, &quaternion_manifold);
      if (problem->poses[o.pose_index].fixed) {
        ceres_problem.SetParameterBlockConstant(qi);
        ceres_problem.SetParameterBlockConstant(ti);
      }
    }
    if (!point_added[o.point_index]) {
      point_added[o.point_index] = true;
      if (problem->points[o.point_index].fixed) ceres_problem.SetParameterBlockConstant(xj);
    }
  }

  ceres::Solver::Options solver_options;
  solver_options.minimizer_type = ceres::TRUST_REGION;
  solver_options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  ChooseLinearSolver(&solver_options);
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.num_threads = options.num_threads;
  solver_options.logging_type = ceres::SILENT;
  std::unique_ptr<AbortCallback> callback;
  if (abort_flag != nullptr) {
    callback = std::make_unique<AbortCallback>(abort_flag);
    solver_options.callbacks.push_back(callback.get());
  }
  ceres::Solver::Summary ceres_summary;
  if (problem->observations.empty()) {
    summary.usable = true;
    return summary;
  }
  ceres::Solve(solver_options, &ceres_problem, &ceres_summary);
  // ceres_summary.iterations starts with iteration 0 (the initial evaluation, no step).
  summary.iterations = std::max(0, static_cast<int>(ceres_summary.iterations.size()) - 1);
  summary.initial_cost = ceres_summary.initial_cost;
  summary.final_cost = ceres_summary.final_cost;
  summary.usable = ceres_summary.IsSolutionUsable();

  for (size_t i = 0; i < num_poses; ++i) {
    if (problem->poses[i].fixed) continue;
    problem->poses[i].cam_from_world =
        Rigid3d(Eigen::Quaterniond(Eigen::Map<const Eigen::Vector4d>(&q[4 * i])),
                Eigen::Vector3d(Eigen::Map<const Eigen::Vector3d>(&t[3 * i])));
  }
  for (size_t j = 0; j < problem->points.size(); ++j) {
    if (!problem->points[j].fixed) problem->points[j].p_world = Eigen::Vector3d(&x[3 * j]);
  }
  summary.outlier = ClassifyObservations(camera, *problem, options);
  return summary;
}

}  // namespace

}  // namespace detslam
