// Relative pose error with the semantics of the TUM RGB-D benchmark's evaluate_rpe.py run with
// --fixed_delta (papers: --fixed_delta --delta 1 --delta_unit s):
// - pairs (i, j) are formed over the estimate's sorted stamps: for every i, j is the estimate
//   index whose key is closest to key_i + delta, where the key is the stamp (unit s) or the index
//   (unit frames). A pair is dropped when j is the last estimate index (this drops pairs that
//   would run past the end, and, as in evaluate_rpe.py, also a pair that ends exactly on the last
//   pose). Pairs are kept across tracking gaps (then t_j - t_i exceeds delta). Ties between two
//   equally close stamps go to the earlier one. Unlike evaluate_rpe.py we never subsample: all
//   pairs are used (evaluate_rpe.py samples 10000 at random when there are more).
// - each est stamp is matched to the closest ground-truth stamp to (t_est + offset); the pair is
//   dropped if either match is further than 2 x the median ground-truth stamp interval.
// - with P = world_from_cam, the error is E = (P_est_j^-1 P_est_i)^-1 (P_gt_j^-1 P_gt_i), i.e.
//   evaluate_rpe.py's ominus(ominus(est_j, est_i), ominus(gt_j, gt_i)). trans = |t(E)| (m), rot =
//   arccos(clamp((tr R(E) - 1) / 2)) (deg). The angle equals that of evo's (gt_ij)^-1 est_ij
//   form; the translation norm equals it whenever the relative rotations agree.
// - per-second values (m/s, deg/s) are the errors divided by delta for the seconds unit (delta
//   = 1 s: identical numbers), as papers report them. For the frames unit the values are per frame
//   pair (m, deg) and no per-second value is formed.
#pragma once

#include <string>
#include <vector>

#include "detslam/core/stats.h"
#include "detslam/io/trajectory.h"

namespace detslam {

enum class RpeDeltaUnit { kSeconds, kFrames };

struct RpeOptions {
  double delta = 1.0;                          // window length in `unit` (> 0; integer frames)
  RpeDeltaUnit unit = RpeDeltaUnit::kSeconds;  // seconds (papers) or frames (per-frame drift)
  double offset_s = 0.0;                       // added to est stamps before gt lookup (seconds)

  bool Check(std::string* error) const;
};

struct RpePair {
  Timestamp est_from, est_to;  // estimate stamps i, j
  Timestamp gt_from, gt_to;    // matched ground-truth stamps
  double trans_m = 0.0;
  double rot_deg = 0.0;
};

struct RpeResult {
  RpeOptions options;
  std::vector<RpePair> pairs;  // in the order of i
  ErrorStats trans_m;          // translational error per pair (metres)
  ErrorStats rot_deg;          // rotational error per pair (degrees)
  // trans_m / rot_deg divided by delta (m/s, deg/s); only meaningful for the seconds unit.
  ErrorStats TransPerSecond() const;
  ErrorStats RotPerSecond() const;
  bool per_second() const { return options.unit == RpeDeltaUnit::kSeconds; }
};

// Trajectories must be sorted by stamp without duplicates (CHECK) and options valid (CHECK).
// Returns no pairs (count 0) when the trajectories do not overlap; never throws.
RpeResult ComputeRpe(const Trajectory& gt, const Trajectory& est, const RpeOptions& options);

// Index of the stamp closest to `t` in sorted `stamps` (non-empty); ties go to the earlier stamp.
size_t ClosestIndex(const std::vector<Timestamp>& stamps, Timestamp t);

const char* RpeDeltaUnitName(RpeDeltaUnit unit);

}  // namespace detslam
