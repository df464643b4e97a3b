#include "detslam/geometry/ransac_options.h"

#include <cmath>
#include <sstream>

namespace detslam {

bool RansacOptions::Check(std::string* error) const {
  std::ostringstream os;
  if (max_iterations <= 0) os << "max_iterations must be positive; ";
  if (!(probability > 0.0 && probability < 1.0)) os << "probability must be in (0, 1); ";
  if (min_inliers < 0) os << "min_inliers must not be negative; ";
  if (!(chi2_threshold > 0.0)) os << "chi2_threshold must be positive; ";
  if (error != nullptr) *error = os.str();
  return os.str().empty();
}

int AdaptiveIterations(double inlier_ratio, int sample_size, double probability,
                       int max_iterations) {
  if (inlier_ratio <= 0.0) return max_iterations;
  if (inlier_ratio >= 1.0) return 1;
  const double all_inlier = std::pow(inlier_ratio, sample_size);
  if (all_inlier <= 0.0) return max_iterations;
  const double n = std::log(1.0 - probability) / std::log1p(-all_inlier);
  if (!std::isfinite(n) || n >= max_iterations) return max_iterations;
  return std::max(1, static_cast<int>(std::ceil(n)));
}

}  // namespace detslam
