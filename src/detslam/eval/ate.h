// Absolute trajectory error with the semantics of the TUM RGB-D benchmark's evaluate_ate.py:
// - estimate and ground truth are associated like associate.py: greedy one-to-one matching of
//   |t_gt - (t_est + offset)| < max_difference (default 0.02 s), closest pairs first
//   (core/association.h, called with the ground truth as the first list, as evaluate_ate.py does);
// - the estimated camera positions are aligned to the ground-truth positions in closed form
//   (Horn/Umeyama on positions only; rotation + translation, plus scale only with `with_scale`);
// - the error of a pair is |gt_position - aligned_est_position| in metres; orientations are
//   ignored, as in evaluate_ate.py and evo_ape's default trans_part relation.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "detslam/core/association.h"
#include "detslam/core/stats.h"
#include "detslam/geometry/alignment.h"
#include "detslam/io/trajectory.h"

namespace detslam {

struct AteOptions {
  AssociationOptions association;  // est<->gt matching window and est clock offset (seconds)
  bool with_scale = false;         // Sim(3) alignment (monocular-style); RGB-D results use false
};

struct AtePair {
  Timestamp gt_stamp;
  Timestamp est_stamp;
  Eigen::Vector3d gt_position;
  Eigen::Vector3d est_aligned;  // estimated position after the alignment (for plots)
  double error_m = 0.0;
};

struct AteResult {
  Alignment gt_from_est;       // maps estimate positions into the ground-truth frame
  std::vector<AtePair> pairs;  // in ground-truth time order
  ErrorStats error_m;          // statistics of the per-pair errors (metres)
};

// Trajectories must be sorted by stamp without duplicates (CHECK; see PrepareTrajectory).
// Throws InputError (no file; the caller adds it) if fewer than 3 pairs associate.
AteResult ComputeAte(const Trajectory& gt, const Trajectory& est, const AteOptions& options);

// CHECKs that stamps strictly increase.
void CheckSortedUnique(const Trajectory& trajectory);

}  // namespace detslam
