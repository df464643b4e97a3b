#include "detslam/viewer/viewer_content.h"

#include <algorithm>

#include "detslam/core/check.h"
#include "detslam/eval/ate.h"

namespace detslam {

const char* KeypointFateName(KeypointFate fate) {
  switch (fate) {
    case KeypointFate::kMatched: return "matched";
    case KeypointFate::kUnmatched: return "unmatched";
    case KeypointFate::kMask: return "mask";
    case KeypointFate::kDepth: return "depth";
    case KeypointFate::kGeometric: return "geometric";
  }
  return "?";
}

Trajectory SortedUnique(Trajectory trajectory) {
  std::stable_sort(trajectory.begin(), trajectory.end(),
                   [](const StampedPose& a, const StampedPose& b) { return a.stamp < b.stamp; });
  trajectory.erase(std::unique(trajectory.begin(), trajectory.end(),
                               [](const StampedPose& a, const StampedPose& b) {
                                 return a.stamp == b.stamp;
                               }),
                   trajectory.end());
  return trajectory;
}

std::vector<Eigen::Vector3d> GroundTruthInEstimateFrame(const Trajectory& ground_truth,
                                                        const Trajectory& estimate) {
  if (ground_truth.empty() || estimate.size() < 3) return {};
  try {
    const AteResult ate = ComputeAte(ground_truth, estimate, AteOptions());
    const Rigid3d est_from_gt = ate.gt_from_est.b_from_a.Inverse();
    std::vector<Eigen::Vector3d> out;
    out.reserve(ground_truth.size());
    for (const StampedPose& p : ground_truth) out.push_back(est_from_gt * p.world_from_cam.translation());
    return out;
  } catch (const InputError&) {
    return {};  // fewer than 3 poses associate yet
  }
}

}  // namespace detslam
