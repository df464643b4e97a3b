#include "detslam/core/association.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <tuple>

namespace detslam {

std::vector<std::pair<size_t, size_t>> AssociateTimestamps(const std::vector<Timestamp>& a,
                                                           const std::vector<Timestamp>& b,
                                                           const AssociationOptions& options) {
  const int64_t offset_ns = static_cast<int64_t>(std::llround(options.offset_s * 1e9));
  const double max_ns = options.max_difference_s * 1e9;
  // Candidate pairs within the window. Both lists are usually sorted; a sorted copy of b lets
  // us scan only the window around each a.
  std::vector<size_t> b_order(b.size());
  for (size_t j = 0; j < b.size(); ++j) b_order[j] = j;
  std::sort(b_order.begin(), b_order.end(),
            [&](size_t x, size_t y) { return std::tie(b[x].ns, x) < std::tie(b[y].ns, y); });
  std::vector<int64_t> b_shifted(b.size());
  for (size_t k = 0; k < b_order.size(); ++k) b_shifted[k] = b[b_order[k]].ns + offset_ns;

  struct Candidate {
    int64_t diff;
    size_t i, j;
  };
  std::vector<Candidate> candidates;
  const int64_t window = static_cast<int64_t>(std::ceil(max_ns));
  for (size_t i = 0; i < a.size(); ++i) {
    auto it = std::lower_bound(b_shifted.begin(), b_shifted.end(), a[i].ns - window);
    for (; it != b_shifted.end() && *it <= a[i].ns + window; ++it) {
      const int64_t diff = std::llabs(a[i].ns - *it);
      if (static_cast<double>(diff) < max_ns) {
        candidates.push_back({diff, i, b_order[static_cast<size_t>(it - b_shifted.begin())]});
      }
    }
  }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& x, const Candidate& y) {
    return std::tie(x.diff, x.i, x.j) < std::tie(y.diff, y.i, y.j);
  });
  std::vector<bool> used_a(a.size(), false), used_b(b.size(), false);
  std::vector<std::pair<size_t, size_t>> matches;
  for (const Candidate& c : candidates) {
    if (used_a[c.i] || used_b[c.j]) continue;
    used_a[c.i] = used_b[c.j] = true;
    matches.emplace_back(c.i, c.j);
  }
  std::sort(matches.begin(), matches.end());
  return matches;
}

}  // namespace detslam
