// Timestamp association as the TUM RGB-D tools do it (associate.py): greedy one-to-one matching,
// closest pairs first, of |a - (b + offset)| < max_difference.
#pragma once

#include <utility>
#include <vector>

#include "detslam/core/timestamp.h"

namespace detslam {

struct AssociationOptions {
  double max_difference_s = 0.02;  // largest accepted |a - (b + offset)| in seconds (exclusive)
  double offset_s = 0.0;           // added to the second list's stamps before matching
};

// Returns index pairs (i into a, j into b), sorted by i. Each index is used at most once. Ties in
// distance are broken by the smaller (i, j) so the result does not depend on sort stability.
std::vector<std::pair<size_t, size_t>> AssociateTimestamps(const std::vector<Timestamp>& a,
                                                           const std::vector<Timestamp>& b,
                                                           const AssociationOptions& options);

}  // namespace detslam
