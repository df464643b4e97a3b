// Closed-form least-squares alignment of two corresponding point sets (Umeyama 1991; without scale
// this is Horn's / Kabsch's method as used by the TUM RGB-D tool evaluate_ate.py).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "detslam/core/rigid3d.h"

namespace detslam {

// b ≈ scale * (b_from_a.rotation * a) + b_from_a.translation.
// With scale != 1 the pair is a similarity; apply it with ApplyAlignment, not with b_from_a alone.
struct Alignment {
  Rigid3d b_from_a;
  double scale = 1.0;
};

// Minimises sum_i |b_i - (s R a_i + t)|^2 over R in SO(3), t, and s > 0 when `with_scale`
// (s = 1 otherwise). Closed form: SVD of the cross-covariance
// Sigma = 1/n sum (b_i - mb)(a_i - ma)^T = U D V^T, R = U S V^T with S = diag(1, 1, det(U) det(V))
// (the reflection fix), s = tr(D S) / var(a), t = mb - s R ma. Requires a.size() == b.size() >= 3
// (CHECK); with_scale also requires a to have non-zero spread (CHECK). Degenerate sets (collinear
// points) give one of the optimal rotations.
Alignment AlignPointSets(const std::vector<Eigen::Vector3d>& a,
                         const std::vector<Eigen::Vector3d>& b, bool with_scale);

// The rigid b_from_a that best maps poses a_i (world_a_from_cam) onto b_i (world_b_from_cam):
// rotation R = the chordal mean of R_b_i R_a_i^T (SVD projection of their sum onto SO(3)),
// translation t = mean(p_b_i - R p_a_i). Unlike AlignPointSets it is well defined when the
// positions do not span space (a camera that barely moves), e.g. to place a map made along a
// trajectory into the ground truth's frame. Requires a.size() == b.size() >= 1 (CHECK).
Rigid3d AlignPoseSets(const std::vector<Rigid3d>& a, const std::vector<Rigid3d>& b);

// s * (R p + 0) + t, i.e. the aligned position of a point of set a in frame b.
inline Eigen::Vector3d ApplyAlignment(const Alignment& alignment, const Eigen::Vector3d& p_a) {
  return alignment.scale * (alignment.b_from_a.RotationMatrix() * p_a) +
         alignment.b_from_a.translation();
}

}  // namespace detslam
