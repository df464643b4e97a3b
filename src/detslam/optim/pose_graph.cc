#include "detslam/optim/pose_graph.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "detslam/core/check.h"

namespace detslam {

ceres::CostFunction* RelativePoseCost::Create(const Rigid3d& from_from_to, double sqrt_weight) {
  return new ceres::AutoDiffCostFunction<RelativePoseCost, 6, 4, 3, 4, 3>(
      new RelativePoseCost(from_from_to, sqrt_weight));
}

bool PoseGraphOptions::Check(std::string* error) const {
  std::ostringstream os;
  if (max_iterations <= 0) os << "max_iterations must be positive; ";
  if (num_threads <= 0) os << "num_threads must be positive; ";
  if (error != nullptr) *error = os.str();
  return os.str().empty();
}

PoseGraphSummary SolvePoseGraph(PoseGraphProblem* problem, const PoseGraphOptions& options) {
  DETSLAM_CHECK(problem != nullptr);
  std::string error;
  if (!options.Check(&error)) throw InputError("SolvePoseGraph options: " + error);
  const size_t n = problem->nodes.size();
  for (const PoseGraphProblem::Edge& e : problem->edges) {
    if (e.from >= n || e.to >= n || e.from == e.to) {
      throw InputError("SolvePoseGraph: edge refers to a missing node or to itself");
    }
    if (!(e.weight > 0.0)) throw InputError("SolvePoseGraph: edge weights must be positive");
  }
  PoseGraphSummary summary;
  if (problem->edges.empty()) {
    summary.usable = true;
    return summary;
  }
  std::vector<double> q(4 * n), t(3 * n);
  for (size_t i = 0; i < n; ++i) {
    Eigen::Map<Eigen::Vector4d> qi(&q[4 * i]);
    Eigen::Map<Eigen::Vector3d> ti(&t[3 * i]);
    qi = problem->nodes[i].cam_from_world.rotation().coeffs();
    ti = problem->nodes[i].cam_from_world.translation();
  }
  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem ceres_problem(problem_options);
  ceres::EigenQuaternionManifold quaternion_manifold;
  std::vector<bool> added(n, false);
  for (const PoseGraphProblem::Edge& e : problem->edges) {
    ceres_problem.AddResidualBlock(RelativePoseCost::Create(e.from_from_to, std::sqrt(e.weight)),
                                   nullptr, &q[4 * e.from], &t[3 * e.from], &q[4 * e.to],
                                   &t[3 * e.to]);
    for (const size_t i : {e.from, e.to}) {
      if (added[i]) continue;
      added[i] = true;
      ceres_problem.SetManifold(&q[4 * i], &quaternion_manifold);
      if (i == 0 || problem->nodes[i].fixed) {
        ceres_problem.SetParameterBlockConstant(&q[4 * i]);
        ceres_problem.SetParameterBlockConstant(&t[3 * i]);
      }
    }
  }
  ceres::Solver::Options solver_options;
  solver_options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  solver_options.linear_solver_type =
      ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::SUITE_SPARSE)
          ? ceres::SPARSE_NORMAL_CHOLESKY
          : ceres::DENSE_QR;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.num_threads = options.num_threads;
  solver_options.logging_type = ceres::SILENT;
  ceres::Solver::Summary ceres_summary;
  ceres::Solve(solver_options, &ceres_problem, &ceres_summary);
  summary.iterations = std::max(0, static_cast<int>(ceres_summary.iterations.size()) - 1);
  summary.initial_cost = ceres_summary.initial_cost;
  summary.final_cost = ceres_summary.final_cost;
  summary.usable = ceres_summary.IsSolutionUsable();
  for (size_t i = 1; i < n; ++i) {
    if (!added[i] || problem->nodes[i].fixed) continue;
    problem->nodes[i].cam_from_world =
        Rigid3d(Eigen::Quaterniond(Eigen::Map<const Eigen::Vector4d>(&q[4 * i])),
                Eigen::Vector3d(&t[3 * i]));
  }
  return summary;
}

}  // namespace detslam
