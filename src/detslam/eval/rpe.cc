#include "detslam/eval/rpe.h"

#include <algorithm>
#include <cmath>

#include "detslam/core/check.h"
#include "detslam/eval/ate.h"

namespace detslam {

bool RpeOptions::Check(std::string* error) const {
  if (!(delta > 0.0) || !std::isfinite(delta)) {
    *error = "RPE delta must be positive";
    return false;
  }
  if (unit == RpeDeltaUnit::kFrames && delta != std::floor(delta)) {
    *error = "RPE delta in frames must be a whole number";
    return false;
  }
  if (!std::isfinite(offset_s)) {
    *error = "RPE offset must be finite";
    return false;
  }
  return true;
}

ErrorStats RpeResult::TransPerSecond() const { return ScaleErrorStats(trans_m, 1.0 / options.delta); }
ErrorStats RpeResult::RotPerSecond() const { return ScaleErrorStats(rot_deg, 1.0 / options.delta); }

const char* RpeDeltaUnitName(RpeDeltaUnit unit) {
  return unit == RpeDeltaUnit::kSeconds ? "s" : "frames";
}

size_t ClosestIndex(const std::vector<Timestamp>& stamps, Timestamp t) {
  DETSLAM_CHECK(!stamps.empty());
  const auto it = std::lower_bound(stamps.begin(), stamps.end(), t);
  if (it == stamps.begin()) return 0;
  if (it == stamps.end()) return stamps.size() - 1;
  const size_t hi = static_cast<size_t>(it - stamps.begin());
  const size_t lo = hi - 1;
  // Earlier stamp wins a tie.
  return (t.ns - stamps[lo].ns) <= (stamps[hi].ns - t.ns) ? lo : hi;
}

namespace {

double RotationAngleDeg(const Eigen::Matrix3d& r) {
  const double c = std::clamp((r.trace() - 1.0) / 2.0, -1.0, 1.0);
  return std::acos(c) * 180.0 / M_PI;
}

double MedianIntervalNs(const std::vector<Timestamp>& stamps) {
  std::vector<double> d;
  for (size_t k = 1; k < stamps.size(); ++k) d.push_back(static_cast<double>(stamps[k].ns - stamps[k - 1].ns));
  return ComputeErrorStats(d).median;
}

}  // namespace

RpeResult ComputeRpe(const Trajectory& gt, const Trajectory& est, const RpeOptions& options) {
  std::string why;
  DETSLAM_CHECK_MSG(options.Check(&why), why);
  CheckSortedUnique(gt);
  CheckSortedUnique(est);
  RpeResult result;
  result.options = options;
  if (gt.size() < 2 || est.size() < 2) return result;

  std::vector<Timestamp> gt_stamps, est_stamps;
  for (const StampedPose& p : gt) gt_stamps.push_back(p.stamp);
  for (const StampedPose& p : est) est_stamps.push_back(p.stamp);
  const int64_t offset_ns = static_cast<int64_t>(std::llround(options.offset_s * 1e9));
  const double max_gt_diff_ns = 2.0 * MedianIntervalNs(gt_stamps);
  const size_t n = est.size();
  const int64_t delta_ns = static_cast<int64_t>(std::llround(options.delta * 1e9));
  const size_t delta_frames = static_cast<size_t>(std::llround(options.delta));

  std::vector<double> trans, rot;
  for (size_t i = 0; i < n; ++i) {
    const size_t j = options.unit == RpeDeltaUnit::kSeconds
                         ? ClosestIndex(est_stamps, Timestamp{est_stamps[i].ns + delta_ns})
                         : std::min(i + delta_frames, n - 1);
    if (j == n - 1) continue;
    const Timestamp gi_query{est_stamps[i].ns + offset_ns};
    const Timestamp gj_query{est_stamps[j].ns + offset_ns};
    const size_t gi = ClosestIndex(gt_stamps, gi_query);
    const size_t gj = ClosestIndex(gt_stamps, gj_query);
    if (std::abs(static_cast<double>(gt_stamps[gi].ns - gi_query.ns)) > max_gt_diff_ns ||
        std::abs(static_cast<double>(gt_stamps[gj].ns - gj_query.ns)) > max_gt_diff_ns) {
      continue;
    }
    const Rigid3d est_j_from_i = est[j].world_from_cam.Inverse() * est[i].world_from_cam;
    const Rigid3d gt_j_from_i = gt[gj].world_from_cam.Inverse() * gt[gi].world_from_cam;
    const Rigid3d error = est_j_from_i.Inverse() * gt_j_from_i;
    RpePair pair;
    pair.est_from = est_stamps[i];
    pair.est_to = est_stamps[j];
    pair.gt_from = gt_stamps[gi];
    pair.gt_to = gt_stamps[gj];
    pair.trans_m = error.translation().norm();
    pair.rot_deg = RotationAngleDeg(error.RotationMatrix());
    trans.push_back(pair.trans_m);
    rot.push_back(pair.rot_deg);
    result.pairs.push_back(pair);
  }
  result.trans_m = ComputeErrorStats(trans);
  result.rot_deg = ComputeErrorStats(rot);
  return result;
}

}  // namespace detslam
