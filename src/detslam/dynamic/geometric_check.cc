#include "detslam/dynamic/geometric_check.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "detslam/core/check.h"

namespace detslam {
namespace {

constexpr double kMadToSigma = 1.4826;

bool ValidResidual(double r) { return r >= 0.0 && std::isfinite(r); }

}  // namespace

bool GeometricCheckOptions::Check(std::string* error) const {
  auto fail = [error](const std::string& message) {
    if (error != nullptr) *error = message;
    return false;
  };
  if (!(k > 0.0 && std::isfinite(k))) return fail("k must be positive");
  if (!(min_threshold >= 0.0 && std::isfinite(min_threshold))) {
    return fail("min_threshold must be non-negative");
  }
  if (min_samples < 1) return fail("min_samples must be at least 1");
  return true;
}

bool MoverCheckOptions::Check(std::string* error) const {
  if (!threshold.Check(error)) return false;
  std::string message;
  if (!(radius_px > 0)) message = "radius_px must be positive";
  if (!(depth_ratio >= 0)) message = "depth_ratio must be non-negative";
  if (min_cluster < 0) message = "min_cluster must be non-negative";
  if (!(carry_window_px > 0)) message = "carry_window_px must be positive";
  if (region_frames < 0) message = "region_frames must be non-negative";
  if (region_min_keypoints < 1) message = "region_min_keypoints must be positive";
  if (!(region_growth_px >= 0)) message = "region_growth_px must be non-negative";
  if (!(region_depth_ratio >= 0 && region_depth_ratio < 1))
    message = "region_depth_ratio must be in [0, 1)";
  if (!(coherence >= 0)) message = "coherence must be non-negative";
  if (error != nullptr) *error = message;
  return message.empty();
}

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  const double upper = values[mid];
  if (values.size() % 2 == 1) return upper;
  const double lower = *std::max_element(values.begin(), values.begin() + mid);
  return 0.5 * (lower + upper);
}

GeometricCheckResult FlagGeometricOutliers(const std::vector<double>& residuals,
                                           const GeometricCheckOptions& options,
                                           std::vector<KeypointLabel>* labels) {
  DETSLAM_CHECK(labels != nullptr);
  DETSLAM_CHECK_MSG(residuals.size() == labels->size(),
                    residuals.size() << " residuals for " << labels->size() << " labels");
  std::string error;
  DETSLAM_CHECK_MSG(options.Check(&error), "invalid GeometricCheckOptions: " << error);
  GeometricCheckResult result;
  result.threshold = std::numeric_limits<double>::infinity();
  std::vector<double> samples;
  samples.reserve(residuals.size());
  for (size_t i = 0; i < residuals.size(); ++i) {
    if ((*labels)[i] == KeypointLabel::kStatic && ValidResidual(residuals[i])) {
      samples.push_back(residuals[i]);
    }
  }
  result.samples = static_cast<int>(samples.size());
  if (samples.empty()) return result;
  result.median = Median(samples);
  for (double& r : samples) r = std::abs(r - result.median);
  result.mad = Median(std::move(samples));
  if (result.samples < options.min_samples) return result;
  result.threshold =
      std::max(options.min_threshold, result.median + options.k * kMadToSigma * result.mad);
  for (size_t i = 0; i < residuals.size(); ++i) {
    if ((*labels)[i] == KeypointLabel::kStatic && ValidResidual(residuals[i]) &&
        residuals[i] > result.threshold) {
      (*labels)[i] = KeypointLabel::kGeometric;
      ++result.flagged;
    }
  }
  return result;
}

}  // namespace detslam
