#include "detslam/geometry/ransac.h"

namespace detslam {

std::vector<int> SampleDistinctIndices(int n, int k, Rng& rng) {
  std::vector<int> out;
  out.reserve(k);
  while (static_cast<int>(out.size()) < k) {
    const int i = rng.UniformInt(0, n - 1);
    if (std::find(out.begin(), out.end(), i) == out.end()) out.push_back(i);
  }
  return out;
}

std::vector<int> MaskIndices(const std::vector<bool>& mask) {
  std::vector<int> out;
  for (size_t i = 0; i < mask.size(); ++i) {
    if (mask[i]) out.push_back(static_cast<int>(i));
  }
  return out;
}

}  // namespace detslam
