#include "detslam/optim/pose_optimizer.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <sstream>

#include "detslam/core/check.h"
#include "detslam/geometry/projection.h"
#include "detslam/optim/robust_cost.h"

namespace detslam {
namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

struct Observation {
  const PoseObservation* obs;
  bool stereo;
  double chi2_threshold;
  double huber_delta;
  double sqrt_info;  // sqrt of the keypoint octave's information
};

// Whitened residual (ObservationResidual); false when the point is not in front.
bool Residual(const PinholeCamera& camera, const Observation& o, const Rigid3d& pose,
              Eigen::Vector3d* p_cam, Eigen::Vector3d* r) {
  *p_cam = pose * o.obs->point_world;
  return ObservationResidual(camera, *p_cam, o.obs->uv, o.obs->u_right, o.sqrt_info, o.stereo, r);
}

class PoseProblem {
 public:
  PoseProblem(const PinholeCamera& camera, std::vector<Observation> observations)
      : camera_(camera), obs_(std::move(observations)) {}

  double Cost(const Rigid3d& pose, const std::vector<bool>& active, bool robust) const {
    double total = 0.0;
    Eigen::Vector3d p_cam, r;
    for (size_t i = 0; i < obs_.size(); ++i) {
      if (!active[i] || !Residual(camera_, obs_[i], pose, &p_cam, &r)) continue;
      double cost, weight;
      Robustify(r.squaredNorm(), obs_[i].huber_delta, robust, &cost, &weight);
      total += cost;
    }
    return total;
  }

  // Gauss-Newton system of the robustified cost; returns the cost.
  double Linearize(const Rigid3d& pose, const std::vector<bool>& active, bool robust, Matrix6d* h,
                   Vector6d* g) const {
    h->setZero();
    g->setZero();
    double total = 0.0;
    Eigen::Vector3d p_cam, r;
    for (size_t i = 0; i < obs_.size(); ++i) {
      if (!active[i] || !Residual(camera_, obs_[i], pose, &p_cam, &r)) continue;
      double cost, weight;
      Robustify(r.squaredNorm(), obs_[i].huber_delta, robust, &cost, &weight);
      total += cost;
      // Whitened Jacobian: (u, v) rows times sqrt_info; the disparity bf / z has the Jacobian
      // d(u)/d(delta) - d(u_right)/d(delta).
      const Eigen::Matrix<double, 3, 6> jp = StereoPoseJacobian(camera_, p_cam);
      Eigen::Matrix<double, 3, 6> j = obs_[i].sqrt_info * jp;
      if (camera_.disparity_sigma > 0) j.row(2) = (jp.row(0) - jp.row(2)) / camera_.disparity_sigma;
      if (obs_[i].stereo) {
        h->noalias() += weight * j.transpose() * j;
        g->noalias() += weight * j.transpose() * r;
      } else {
        const Eigen::Matrix<double, 2, 6> jm = j.topRows<2>();
        h->noalias() += weight * jm.transpose() * jm;
        g->noalias() += weight * jm.transpose() * r.head<2>();
      }
    }
    return total;
  }

  // Levenberg-Marquardt on the active observations.
  void Optimize(int iterations, const std::vector<bool>& active, bool robust, Rigid3d* pose) const {
    Matrix6d h;
    Vector6d g;
    double lambda = -1.0;
    for (int it = 0; it < iterations; ++it) {
      const double cost = Linearize(*pose, active, robust, &h, &g);
      if (lambda < 0.0) lambda = 1e-5 * h.diagonal().maxCoeff();
      bool improved = false;
      for (int attempt = 0; attempt < 10 && !improved; ++attempt) {
        Matrix6d damped = h;
        damped.diagonal().array() += lambda;
        const Vector6d delta = damped.ldlt().solve(-g);
        if (!delta.allFinite()) return;
        const Rigid3d candidate = Rigid3d::Exp(delta) * (*pose);
        const double new_cost = Cost(candidate, active, robust);
        if (new_cost < cost) {
          *pose = candidate;
          lambda = std::max(lambda / 3.0, 1e-12);
          improved = true;
          if (delta.squaredNorm() < 1e-20 || cost - new_cost < 1e-12 * cost) return;
        } else {
          lambda *= 4.0;
        }
      }
      if (!improved) return;  // no decrease possible: converged
    }
  }

  int Classify(const Rigid3d& pose, std::vector<bool>* inliers) const {
    int count = 0;
    Eigen::Vector3d p_cam, r;
    for (size_t i = 0; i < obs_.size(); ++i) {
      const bool ok =
          Residual(camera_, obs_[i], pose, &p_cam, &r) && r.squaredNorm() <= obs_[i].chi2_threshold;
      (*inliers)[i] = ok;
      count += ok ? 1 : 0;
    }
    return count;
  }

 private:
  const PinholeCamera& camera_;
  std::vector<Observation> obs_;
};

}  // namespace

bool PoseOptimizerOptions::Check(std::string* error) const {
  std::ostringstream os;
  if (rounds <= 0) os << "rounds must be positive; ";
  if (iterations_per_round <= 0) os << "iterations_per_round must be positive; ";
  if (!(chi2_mono > 0.0) || !(chi2_stereo > 0.0)) os << "chi2 thresholds must be positive; ";
  if (error != nullptr) *error = os.str();
  return os.str().empty();
}

Eigen::Matrix<double, 3, 6> StereoPoseJacobian(const PinholeCamera& camera,
                                               const Eigen::Vector3d& p_cam) {
  const double inv_z = 1.0 / p_cam.z();
  const double inv_z2 = inv_z * inv_z;
  Eigen::Matrix3d d_proj;                                             // d(u, v, u_right) / d(p_cam)
  d_proj << camera.fx * inv_z, 0.0, -camera.fx * p_cam.x() * inv_z2,  //
      0.0, camera.fy * inv_z, -camera.fy * p_cam.y() * inv_z2,        //
      camera.fx * inv_z, 0.0, (camera.bf - camera.fx * p_cam.x()) * inv_z2;
  Eigen::Matrix<double, 3, 6> d_pcam;  // d(p_cam) / d(rho, phi): [I, -Hat(p_cam)]
  d_pcam.leftCols<3>().setIdentity();
  d_pcam.rightCols<3>() = -Hat(p_cam);
  return d_proj * d_pcam;
}

PoseOptimizerResult OptimizePose(const PinholeCamera& camera, const Rigid3d& initial_cam_from_world,
                                 const std::vector<PoseObservation>& observations,
                                 const PoseOptimizerOptions& options) {
  std::string error;
  if (!options.Check(&error)) throw InputError("OptimizePose options: " + error);
  std::vector<Observation> obs;
  obs.reserve(observations.size());
  for (const PoseObservation& o : observations) {
    const bool stereo = o.u_right >= 0.0;
    const double chi2 = stereo ? options.chi2_stereo : options.chi2_mono;
    obs.push_back({&o, stereo, chi2, std::sqrt(chi2), std::sqrt(o.inv_sigma2)});
  }
  const PoseProblem problem(camera, std::move(obs));
  PoseOptimizerResult result;
  result.cam_from_world = initial_cam_from_world;
  result.inliers.assign(observations.size(), true);
  result.num_inliers = static_cast<int>(observations.size());
  bool classified = false;
  for (int round = 0; round < options.rounds; ++round) {
    if (result.num_inliers < 3) break;  // too few constraints for 6 DoF
    const bool robust = round < options.rounds - 1;
    problem.Optimize(options.iterations_per_round, result.inliers, robust, &result.cam_from_world);
    result.num_inliers = problem.Classify(result.cam_from_world, &result.inliers);
    classified = true;
  }
  if (!classified) result.num_inliers = problem.Classify(result.cam_from_world, &result.inliers);
  return result;
}

}  // namespace detslam
