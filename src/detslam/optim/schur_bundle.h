// Bundle adjustment of a window of keyframes (local BA) without Ceres: Levenberg-Marquardt on the
// reduced camera system (the points eliminated by the Schur complement), factorised densely.
// The residuals are those of SolveBundle's Ceres path (cost_functions.h: whitened (u, v) and
// disparity or u_right), the poses perturbed on the left, cam_from_world <- Exp(rho, phi) *
// cam_from_world, as in OptimizePose; the Huber kernel applied by iteratively reweighted least
// squares (weight rho'); the trust region grown and shrunk as Ceres's Levenberg-Marquardt strategy
// does (same initial radius, step acceptance, damping diagonal and tolerances). Without Ceres's
// general machinery (per-block virtual calls, quaternion manifold products, locked cells of its
// sparse Schur complement) a 20-keyframe local bundle takes a fraction of the time
// (bench/bench_bundle.cc BM_LocalBundle).
#pragma once

#include <atomic>

#include "detslam/core/camera.h"
#include "detslam/optim/bundle_adjustment.h"

namespace detslam {

// Optimises the non-fixed poses and points of a problem SolveBundle has checked (indices in range,
// positive information, at least one fixed pose) in place. Fills iterations (every step tried,
// taken or not, as Ceres counts), initial_cost and final_cost (0.5 * sum of robustified chi2 over
// the observations of a non-fixed pose or point, in front of their camera) and usable (false when
// the cost is not finite); the outlier flags are left to the caller. The reduced system is
// (6 x free poses)^2 dense: meant for windows (SolveBundle hands larger problems to Ceres).
BundleSummary SolveBundleDenseSchur(const PinholeCamera& camera, BundleProblem* problem,
                                    const BundleOptions& options,
                                    const std::atomic<bool>* abort_flag = nullptr);

}  // namespace detslam
