#include "detslam/optim/schur_bundle.h"

#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "detslam/core/rigid3d.h"
#include "detslam/geometry/projection.h"
#include "detslam/optim/pose_optimizer.h"
#include "detslam/optim/robust_cost.h"

namespace detslam {
// Named, not anonymous: a unity build puts pose_optimizer.cc's constants beside these.
namespace schur_bundle_internal {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix63 = Eigen::Matrix<double, 6, 3>;
using Matrix36 = Eigen::Matrix<double, 3, 6>;

// Ceres's Solver::Options defaults for the trust region and the stopping rules.
constexpr double kInitialRadius = 1e4;
constexpr double kMaxRadius = 1e16;
constexpr double kMinRadius = 1e-32;
constexpr double kMinDiagonal = 1e-6;
constexpr double kMaxDiagonal = 1e32;
constexpr double kMinRelativeDecrease = 1e-3;
constexpr double kFunctionTolerance = 1e-6;
constexpr double kGradientTolerance = 1e-10;
constexpr double kParameterTolerance = 1e-8;

// One observation with its variables: -1 where the pose or point is fixed.
struct Term {
  int pose = 0, point = 0;        // into the problem's poses / points
  int pose_var = -1, point_var = -1;
  bool stereo = false;
  double sqrt_info = 1.0;
  double huber_delta = 1.0;
  const BundleProblem::Observation* obs = nullptr;
};

class Window {
 public:
  Window(const PinholeCamera& camera, const BundleProblem& problem, const BundleOptions& options)
      : camera_(camera) {
    std::vector<int>& pose_var = pose_var_of_;
    std::vector<int>& point_var = point_var_of_;
    pose_var.assign(problem.poses.size(), -1);
    point_var.assign(problem.points.size(), -1);
    for (size_t i = 0; i < problem.poses.size(); ++i) {
      poses_.push_back(problem.poses[i].cam_from_world);
      if (!problem.poses[i].fixed) pose_var[i] = num_pose_vars_++;
    }
    for (size_t j = 0; j < problem.points.size(); ++j) {
      points_.push_back(problem.points[j].p_world);
      if (!problem.points[j].fixed) point_var[j] = num_point_vars_++;
    }
    for (const BundleProblem::Observation& o : problem.observations) {
      Term t;
      t.pose = static_cast<int>(o.pose_index);
      t.point = static_cast<int>(o.point_index);
      t.pose_var = pose_var[o.pose_index];
      t.point_var = point_var[o.point_index];
      // Ceres drops residual blocks whose parameters are all constant; so does this.
      if (t.pose_var < 0 && t.point_var < 0) continue;
      t.stereo = o.u_right >= 0.0;
      t.sqrt_info = std::sqrt(o.inv_sigma2);
      t.huber_delta = std::sqrt(t.stereo ? options.chi2_stereo : options.chi2_mono);
      t.obs = &o;
      terms_.push_back(t);
    }
    // The terms of each free point, for the elimination (compressed rows).
    point_terms_start_.assign(num_point_vars_ + 1, 0);
    for (const Term& t : terms_) {
      if (t.point_var >= 0) ++point_terms_start_[t.point_var + 1];
    }
    for (int m = 0; m < num_point_vars_; ++m) point_terms_start_[m + 1] += point_terms_start_[m];
    point_terms_.resize(point_terms_start_.back());
    std::vector<int> fill(point_terms_start_.begin(), point_terms_start_.end() - 1);
    for (size_t k = 0; k < terms_.size(); ++k) {
      if (terms_[k].point_var >= 0) point_terms_[fill[terms_[k].point_var]++] = static_cast<int>(k);
    }
    hpp_.resize(num_pose_vars_);
    gp_.resize(num_pose_vars_);
    hll_.resize(num_point_vars_);
    gl_.resize(num_point_vars_);
    hpl_.resize(terms_.size());
    cinv_.resize(num_point_vars_);
  }

  const std::vector<Rigid3d>& poses() const { return poses_; }
  const std::vector<Eigen::Vector3d>& points() const { return points_; }

  // 0.5 * sum of the robustified chi2 at the given state (Ceres's cost).
  double Cost(const std::vector<Rigid3d>& poses, const std::vector<Eigen::Vector3d>& points) const {
    double total = 0.0;
    Eigen::Vector3d p_cam, r;
    for (const Term& t : terms_) {
      if (!Residual(t, poses[t.pose], points[t.point], &p_cam, &r)) continue;
      double cost, weight;
      Robustify(r.squaredNorm(), t.huber_delta, true, &cost, &weight);
      total += cost;
    }
    return 0.5 * total;
  }

  // The Gauss-Newton blocks at the current state (IRLS weights); returns the cost.
  double Linearize() {
    for (Matrix6d& h : hpp_) h.setZero();
    for (Vector6d& g : gp_) g.setZero();
    for (Eigen::Matrix3d& h : hll_) h.setZero();
    for (Eigen::Vector3d& g : gl_) g.setZero();
    double total = 0.0;
    Eigen::Vector3d p_cam, r;
    for (size_t k = 0; k < terms_.size(); ++k) {
      const Term& t = terms_[k];
      hpl_[k].setZero();
      if (!Residual(t, poses_[t.pose], points_[t.point], &p_cam, &r)) continue;
      double cost, weight;
      Robustify(r.squaredNorm(), t.huber_delta, true, &cost, &weight);
      total += cost;
      // Whitened Jacobians, as OptimizePose's: (u, v) rows times sqrt_info; the disparity bf / z
      // has the Jacobian d(u) - d(u_right); a mono observation has no third row.
      const Matrix36 jraw = StereoPoseJacobian(camera_, p_cam);
      Matrix36 jp = t.sqrt_info * jraw;
      if (!t.stereo) {
        jp.row(2).setZero();
      } else if (camera_.disparity_sigma > 0) {
        jp.row(2) = (jraw.row(0) - jraw.row(2)) / camera_.disparity_sigma;
      }
      // d p_cam / d p_world is the rotation; the first three columns are d / d p_cam.
      const Eigen::Matrix3d jl = jp.leftCols<3>() * poses_[t.pose].RotationMatrix();
      if (t.pose_var >= 0) {
        hpp_[t.pose_var].noalias() += weight * jp.transpose() * jp;
        gp_[t.pose_var].noalias() += weight * jp.transpose() * r;
      }
      if (t.point_var >= 0) {
        hll_[t.point_var].noalias() += weight * jl.transpose() * jl;
        gl_[t.point_var].noalias() += weight * jl.transpose() * r;
      }
      if (t.pose_var >= 0 && t.point_var >= 0) hpl_[k].noalias() = weight * jp.transpose() * jl;
    }
    return 0.5 * total;
  }

  // Largest gradient entry at the last linearisation.
  double GradientMax() const {
    double m = 0.0;
    for (const Vector6d& g : gp_) m = std::max(m, g.cwiseAbs().maxCoeff());
    for (const Eigen::Vector3d& g : gl_) m = std::max(m, g.cwiseAbs().maxCoeff());
    return m;
  }

  // Solves (H + lambda D) delta = -g by the Schur complement of the points, D the clamped
  // diagonal of H (Ceres's Levenberg-Marquardt regulariser); returns the model's cost reduction
  // (> 0) or a non-positive value when the system could not be solved.
  double Step(double lambda, Eigen::VectorXd* dp, std::vector<Eigen::Vector3d>* dl) {
    const int np = num_pose_vars_;
    s_.setZero(6 * np, 6 * np);
    Eigen::VectorXd rhs(6 * np);
    double model = 0.0;  // lambda * delta^T D delta, completed below
    std::vector<Vector6d> dpose_diag(np);
    for (int k = 0; k < np; ++k) {
      dpose_diag[k] = Clamped<6>(hpp_[k].diagonal());
      s_.block<6, 6>(6 * k, 6 * k) = hpp_[k];
      s_.block<6, 6>(6 * k, 6 * k).diagonal() += lambda * dpose_diag[k];
      rhs.segment<6>(6 * k) = -gp_[k];
    }
    std::vector<Eigen::Vector3d> dpoint_diag(num_point_vars_);
    for (int m = 0; m < num_point_vars_; ++m) {
      dpoint_diag[m] = Clamped<3>(hll_[m].diagonal());
      Eigen::Matrix3d c = hll_[m];
      c.diagonal() += lambda * dpoint_diag[m];
      bool invertible = false;
      c.computeInverseWithCheck(cinv_[m], invertible, 1e-300);
      if (!invertible || !cinv_[m].allFinite()) return -1.0;
      // S -= W C^-1 W^T and rhs += W C^-1 g_l over the pairs of this point's free-pose terms.
      const int begin = point_terms_start_[m], end = point_terms_start_[m + 1];
      for (int a = begin; a < end; ++a) {
        const int ka = point_terms_[a];
        const int pa = terms_[ka].pose_var;
        if (pa < 0) continue;
        const Matrix63 ta = hpl_[ka] * cinv_[m];
        rhs.segment<6>(6 * pa).noalias() += ta * gl_[m];
        s_.block<6, 6>(6 * pa, 6 * pa).noalias() -= ta * hpl_[ka].transpose();
        for (int b = a + 1; b < end; ++b) {
          const int kb = point_terms_[b];
          const int pb = terms_[kb].pose_var;
          if (pb < 0) continue;
          const Matrix6d block = ta * hpl_[kb].transpose();
          s_.block<6, 6>(6 * pa, 6 * pb) -= block;
          s_.block<6, 6>(6 * pb, 6 * pa) -= block.transpose();
        }
      }
    }
    if (np > 0) {
      const Eigen::LDLT<Eigen::MatrixXd> ldlt(s_);
      if (ldlt.info() != Eigen::Success) return -1.0;
      *dp = ldlt.solve(rhs);
      if (!dp->allFinite()) return -1.0;
    } else {
      dp->resize(0);
    }
    for (int k = 0; k < np; ++k) {
      const Vector6d x = dp->segment<6>(6 * k);
      model += lambda * x.dot(dpose_diag[k].cwiseProduct(x)) - x.dot(gp_[k]);
    }
    dl->resize(num_point_vars_);
    for (int m = 0; m < num_point_vars_; ++m) {
      Eigen::Vector3d b = -gl_[m];
      for (int a = point_terms_start_[m]; a < point_terms_start_[m + 1]; ++a) {
        const int ka = point_terms_[a];
        const int pa = terms_[ka].pose_var;
        if (pa >= 0) b.noalias() -= hpl_[ka].transpose() * dp->segment<6>(6 * pa);
      }
      (*dl)[m] = cinv_[m] * b;
      if (!(*dl)[m].allFinite()) return -1.0;
      model += lambda * (*dl)[m].dot(dpoint_diag[m].cwiseProduct((*dl)[m])) - (*dl)[m].dot(gl_[m]);
    }
    // -(g^T delta + 0.5 delta^T H delta) with (H + lambda D) delta = -g.
    return 0.5 * model;
  }

  // The state moved by a step, and the squared norms of the step and of the state (Ceres's
  // parameter tolerance compares them).
  void Apply(const Eigen::VectorXd& dp, const std::vector<Eigen::Vector3d>& dl,
             std::vector<Rigid3d>* poses, std::vector<Eigen::Vector3d>* points, double* step2,
             double* state2) const {
    *poses = poses_;
    *points = points_;
    *step2 = dp.squaredNorm();
    *state2 = 0.0;
    for (size_t i = 0; i < poses_.size(); ++i) {
      *state2 += 1.0 + poses_[i].translation().squaredNorm();  // unit quaternion, translation
      const int v = pose_var_of_[i];
      if (v >= 0) (*poses)[i] = Rigid3d::Exp(dp.segment<6>(6 * v)) * poses_[i];
    }
    for (size_t j = 0; j < points_.size(); ++j) {
      *state2 += points_[j].squaredNorm();
      const int v = point_var_of_[j];
      if (v >= 0) {
        (*points)[j] += dl[v];
        *step2 += dl[v].squaredNorm();
      }
    }
  }

  void Accept(std::vector<Rigid3d> poses, std::vector<Eigen::Vector3d> points) {
    poses_ = std::move(poses);
    points_ = std::move(points);
  }

 private:
  bool Residual(const Term& t, const Rigid3d& pose, const Eigen::Vector3d& p,
                Eigen::Vector3d* p_cam, Eigen::Vector3d* r) const {
    *p_cam = pose * p;
    return ObservationResidual(camera_, *p_cam, t.obs->uv, t.obs->u_right, t.sqrt_info, t.stereo,
                               r);
  }

  template <int N>
  static Eigen::Matrix<double, N, 1> Clamped(const Eigen::Matrix<double, N, 1>& diagonal) {
    return diagonal.cwiseMax(kMinDiagonal).cwiseMin(kMaxDiagonal);
  }

  const PinholeCamera& camera_;
  std::vector<Rigid3d> poses_;
  std::vector<Eigen::Vector3d> points_;
  int num_pose_vars_ = 0, num_point_vars_ = 0;
  std::vector<int> pose_var_of_, point_var_of_;
  std::vector<Term> terms_;
  std::vector<int> point_terms_start_, point_terms_;
  std::vector<Matrix6d> hpp_;
  std::vector<Vector6d> gp_;
  std::vector<Eigen::Matrix3d> hll_, cinv_;
  std::vector<Eigen::Vector3d> gl_;
  std::vector<Matrix63> hpl_;
  Eigen::MatrixXd s_;
};

}  // namespace schur_bundle_internal

using schur_bundle_internal::Window;

BundleSummary SolveBundleDenseSchur(const PinholeCamera& camera, BundleProblem* problem,
                                    const BundleOptions& options,
                                    const std::atomic<bool>* abort_flag) {
  BundleSummary summary;
  Window window(camera, *problem, options);
  double cost = window.Linearize();
  summary.initial_cost = summary.final_cost = cost;
  if (!std::isfinite(cost)) return summary;
  using namespace schur_bundle_internal;  // NOLINT: the constants above
  double radius = kInitialRadius, decrease_factor = 2.0;
  Eigen::VectorXd dp;
  std::vector<Eigen::Vector3d> dl;
  std::vector<Rigid3d> poses;
  std::vector<Eigen::Vector3d> points;
  int iterations = 0;
  while (iterations < options.max_iterations) {
    if (abort_flag != nullptr && abort_flag->load()) break;
    if (window.GradientMax() <= kGradientTolerance) break;
    ++iterations;
    const double model = window.Step(1.0 / radius, &dp, &dl);
    bool taken = false;
    if (model > 0.0) {
      double step2, state2;
      window.Apply(dp, dl, &poses, &points, &step2, &state2);
      if (std::sqrt(step2) <= (std::sqrt(state2) + kParameterTolerance) * kParameterTolerance) break;
      const double new_cost = window.Cost(poses, points);
      const double ratio = (cost - new_cost) / model;
      if (std::isfinite(new_cost) && ratio > kMinRelativeDecrease) {
        taken = true;
        window.Accept(std::move(poses), std::move(points));
        const double previous = cost;
        cost = window.Linearize();
        radius = std::min(kMaxRadius, radius / std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * ratio - 1.0, 3)));
        decrease_factor = 2.0;
        if (previous - cost <= kFunctionTolerance * previous) break;
      }
    }
    if (!taken) {
      radius /= decrease_factor;
      decrease_factor *= 2.0;
      if (radius < kMinRadius) break;
    }
  }
  summary.iterations = iterations;
  summary.final_cost = cost;
  summary.usable = std::isfinite(cost);
  for (size_t i = 0; i < problem->poses.size(); ++i) {
    if (!problem->poses[i].fixed) problem->poses[i].cam_from_world = window.poses()[i];
  }
  for (size_t j = 0; j < problem->points.size(); ++j) {
    if (!problem->points[j].fixed) problem->points[j].p_world = window.points()[j];
  }
  return summary;
}

}  // namespace detslam
