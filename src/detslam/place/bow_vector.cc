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
  // Merge over the union of words; words in only one vector contribute their full weight.
  double distance = 0.0;
  auto ia = a.begin(), ib = b.begin();
  while (ia != a.end() || ib != b.end()) {
    if (ib == b.end() || (ia != a.end() && ia->first < ib->first)) {
      distance += std::abs(ia->second) / na;
      ++ia;
    } else if (ia == a.end() || ib->first < ia->first) {
      distance += std::abs(ib->second) / nb;
      ++ib;
    } else {
      distance += std::abs(ia->second / na - ib->second / nb);
      ++ia;
      ++ib;
    }
  }
  return std::clamp(1.0 - 0.5 * distance, 0.0, 1.0);
}

std::vector<MatchGroup> SharedNodeGroups(const FeatureVector& a, const FeatureVector& b,
                                         const std::vector<bool>& keep_a) {
  std::vector<MatchGroup> groups;
  auto ia = a.begin();
  auto ib = b.begin();
  while (ia != a.end() && ib != b.end()) {
    if (ia->first < ib->first) {
      ++ia;
    } else if (ib->first < ia->first) {
      ++ib;
    } else {
      MatchGroup g;
      for (const int i : ia->second) {
        if (keep_a.empty() || keep_a[static_cast<size_t>(i)]) g.a.push_back(i);
      }
      g.b = ib->second;
      if (!g.a.empty() && !g.b.empty()) groups.push_back(std::move(g));
      ++ia;
      ++ib;
    }
  }
  return groups;
}

}  // namespace detslam
