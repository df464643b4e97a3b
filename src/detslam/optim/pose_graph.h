// SE(3) pose-graph optimisation (loop closing): nodes are camera poses, edges weighted
// relative-pose measurements; Ceres Levenberg-Marquardt with the quaternion manifold.
#pragma once

#include <ceres/cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "detslam/core/rigid3d.h"

namespace detslam {

struct PoseGraphProblem {
  struct Node {
    int64_t id = -1;  // caller's keyframe id (not used by the solver)
    Rigid3d cam_from_world;
    bool fixed = false;  // held constant; the first node is always held constant
  };
  struct Edge {
    size_t from = 0;       // node index i
    size_t to = 0;         // node index j
    Rigid3d from_from_to;  // measured cam_i_from_cam_j = cam_i_from_world * world_from_cam_j
    double weight = 1.0;   // scales the squared residual (information = weight * I)
  };
  std::vector<Node> nodes;
  std::vector<Edge> edges;
};

struct PoseGraphOptions {
  int max_iterations = 20;  // Levenberg-Marquardt iterations
  int num_threads = 1;      // Ceres threads

  bool Check(std::string* error) const;
};

struct PoseGraphSummary {
  int iterations = 0;
  double initial_cost = 0;
  double final_cost = 0;
  bool usable = false;
};

// Residual of one edge, 6 values: [translation error (m), 2 * vector part of the rotation error
// quaternion] of measured^-1 * (cam_i_from_world * world_from_cam_j), times sqrt(weight).
// Parameters: q_i [x y z w], t_i, q_j, t_j of cam_from_world.
class RelativePoseCost {
 public:
  RelativePoseCost(const Rigid3d& from_from_to, double sqrt_weight)
      : q_inv_(from_from_to.rotation().conjugate()),
        t_(from_from_to.translation()),
        sqrt_weight_(sqrt_weight) {}
  template <typename T>
  bool operator()(const T* qi_p, const T* ti_p, const T* qj_p, const T* tj_p, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> qi(qi_p), qj(qj_p);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> ti(ti_p), tj(tj_p);
    const Eigen::Quaternion<T> q_est = qi * qj.conjugate();
    const Eigen::Matrix<T, 3, 1> t_est = ti - q_est * tj;
    const Eigen::Quaternion<T> q_meas_inv = q_inv_.cast<T>();
    // measured^-1 * estimate = (q_inv * q_est, q_inv * (t_est - t_meas)).
    const Eigen::Quaternion<T> dq = q_meas_inv * q_est;
    const Eigen::Matrix<T, 3, 1> dt = q_meas_inv * (t_est - t_.cast<T>());
    const T sign = dq.w() < T(0) ? T(-1) : T(1);  // shortest rotation
    for (int k = 0; k < 3; ++k) {
      residual[k] = T(sqrt_weight_) * dt(k);
      residual[3 + k] = T(sqrt_weight_) * T(2) * sign * dq.vec()(k);
    }
    return true;
  }
  // AutoDiffCostFunction<RelativePoseCost, 6, 4, 3, 4, 3>; the caller owns it.
  static ceres::CostFunction* Create(const Rigid3d& from_from_to, double sqrt_weight);

 private:
  Eigen::Quaterniond q_inv_;
  Eigen::Vector3d t_;
  double sqrt_weight_;
};

// Optimises the non-fixed node poses in place. Throws InputError on invalid options, indices or
// weights.
PoseGraphSummary SolvePoseGraph(PoseGraphProblem* problem, const PoseGraphOptions& options);

}  // namespace detslam
