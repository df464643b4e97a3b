// Bundle adjustment of keyframe poses and points (local BA / global BA) with Ceres:
// Levenberg-Marquardt, Schur-complement solver, Huber kernels, fixed blocks held constant.
#pragma once

#include <Eigen/Core>
#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "detslam/core/camera.h"
#include "detslam/core/rigid3d.h"

namespace detslam {

// What the optimiser works on: plain values referring to each other by index.
struct BundleProblem {
  struct Pose {
    int64_t id = -1;  // caller's keyframe id (not used by the solver)
    Rigid3d cam_from_world;
    bool fixed = false;  // held constant (anchors the gauge; at least one is needed)
  };
  struct Point {
    int64_t id = -1;  // caller's landmark id (not used by the solver)
    Eigen::Vector3d p_world = Eigen::Vector3d::Zero();
    bool fixed = false;
  };
  struct Observation {
    size_t pose_index = 0;                         // into poses
    size_t point_index = 0;                        // into points
    Eigen::Vector2d uv = Eigen::Vector2d::Zero();  // undistorted keypoint (pixels)
    double u_right = -1;                           // virtual right u; < 0: mono observation
    double inv_sigma2 = 1;                         // information scale of the keypoint's octave
  };
  std::vector<Pose> poses;
  std::vector<Point> points;
  std::vector<Observation> observations;
};

struct BundleOptions {
  int max_iterations = 10;     // Levenberg-Marquardt iterations
  double chi2_mono = 5.991;    // Huber delta^2 and outlier threshold, (u, v) residuals
  double chi2_stereo = 7.815;  // Huber delta^2 and outlier threshold, (u, v, u_right) residuals
  int num_threads = 1;         // Ceres evaluation / linear solver threads
  // Up to this many non-fixed poses the hand-written dense-Schur solver runs (schur_bundle.h: a
  // local BA's window); above it Ceres's sparse Schur (global BA). 0: always Ceres.
  int dense_schur_max_poses = 64;

  bool Check(std::string* error) const;
};

struct BundleSummary {
  int iterations = 0;         // LM iterations taken (0 when aborted before the first step)
  double initial_cost = 0;    // Ceres cost (0.5 * sum of robustified chi2) before
  double final_cost = 0;      // ... and after
  std::vector<bool> outlier;  // per observation: chi2 above threshold or point behind the camera
  bool usable = false;        // false when no pose is fixed (gauge free) or Ceres failed
};

// Optimises the non-fixed poses and points in place. Without a fixed pose the problem is left
// untouched and usable = false. When *abort_flag becomes true the solver stops after the current
// iteration (keeping the progress so far). Throws InputError on invalid options or indices.
BundleSummary SolveBundle(const PinholeCamera& camera, BundleProblem* problem,
                          const BundleOptions& options,
                          const std::atomic<bool>* abort_flag = nullptr);

}  // namespace detslam
