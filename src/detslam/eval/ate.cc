#include "detslam/eval/ate.h"

#include <string>

#include "detslam/core/check.h"

namespace detslam {

void CheckSortedUnique(const Trajectory& trajectory) {
  for (size_t i = 1; i < trajectory.size(); ++i) {
    DETSLAM_CHECK_MSG(trajectory[i - 1].stamp < trajectory[i].stamp,
                      "trajectory stamps must strictly increase at index " << i);
  }
}

AteResult ComputeAte(const Trajectory& gt, const Trajectory& est, const AteOptions& options) {
  CheckSortedUnique(gt);
  CheckSortedUnique(est);
  std::vector<Timestamp> gt_stamps, est_stamps;
  for (const StampedPose& p : gt) gt_stamps.push_back(p.stamp);
  for (const StampedPose& p : est) est_stamps.push_back(p.stamp);
  const auto matches = AssociateTimestamps(gt_stamps, est_stamps, options.association);
  if (matches.size() < 3) {
    throw InputError("only " + std::to_string(matches.size()) +
                     " estimated poses lie within " +
                     std::to_string(options.association.max_difference_s) +
                     " s of a ground-truth pose (offset " +
                     std::to_string(options.association.offset_s) +
                     " s); ATE alignment needs at least 3 associated pairs");
  }
  std::vector<Eigen::Vector3d> est_positions, gt_positions;
  for (const auto& [i, j] : matches) {
    gt_positions.push_back(gt[i].world_from_cam.translation());
    est_positions.push_back(est[j].world_from_cam.translation());
  }
  if (options.with_scale) {
    bool spread = false;
    for (const Eigen::Vector3d& p : est_positions) spread |= (p != est_positions.front());
    if (!spread) {
      throw InputError("all associated estimated positions are identical; scale alignment needs "
                       "a moving estimate");
    }
  }
  AteResult result;
  result.gt_from_est = AlignPointSets(est_positions, gt_positions, options.with_scale);
  std::vector<double> errors;
  for (size_t k = 0; k < matches.size(); ++k) {
    AtePair pair;
    pair.gt_stamp = gt[matches[k].first].stamp;
    pair.est_stamp = est[matches[k].second].stamp;
    pair.gt_position = gt_positions[k];
    pair.est_aligned = ApplyAlignment(result.gt_from_est, est_positions[k]);
    pair.error_m = (pair.est_aligned - pair.gt_position).norm();
    errors.push_back(pair.error_m);
    result.pairs.push_back(pair);
  }
  result.error_m = ComputeErrorStats(errors);
  return result;
}

}  // namespace detslam
