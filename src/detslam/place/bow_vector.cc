#include "detslam/place/bow_vector.h"

#include <algorithm>
#include <cmath>

namespace detslam {

double L1Norm(const BowVector& v) {
  double sum = 0.0;
  for (const auto& [word, weight] : v) sum += std::abs(weight);
  return sum;
}

double ScoreL1(const BowVector& a, const BowVector& b) {
  const double na = L1Norm(a), nb = L1Norm(b);
  if (na <= 0.0 || nb <= 0.0) return 0.0;
  // || a' - b' ||_1 over the union of words, with a' = a/|a| and b' = b/|b| (each sums to 1 in
  // absolute value): 2 minus, over the shared words, |a'| + |b'| - |a' - b'|.
  double distance = 2.0;
  ForEachCommonKey(a, b, [&](const auto& x, const auto& y) {
    const double wa = x.second / na, wb = y.second / nb;
    distance -= std::abs(wa) + std::abs(wb) - std::abs(wa - wb);
  });
  return std::clamp(1.0 - 0.5 * distance, 0.0, 1.0);
}

std::vector<MatchGroup> SharedNodeGroups(const FeatureVector& a, const FeatureVector& b,
                                         const std::vector<bool>& keep_a) {
  std::vector<MatchGroup> groups;
  ForEachCommonKey(a, b, [&](const auto& x, const auto& y) {
    MatchGroup g;
    for (const int i : x.second) {
      if (keep_a.empty() || keep_a[static_cast<size_t>(i)]) g.a.push_back(i);
    }
    g.b = y.second;
    if (!g.a.empty() && !g.b.empty()) groups.push_back(std::move(g));
  });
  return groups;
}

}  // namespace detslam
