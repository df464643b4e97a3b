#include "detslam/core/stats.h"

#include <algorithm>
#include <cmath>

namespace detslam {

ErrorStats ComputeErrorStats(const std::vector<double>& values) {
  ErrorStats s;
  s.count = values.size();
  if (values.empty()) return s;
  const double n = static_cast<double>(values.size());
  double sum = 0.0, sum_sq = 0.0;
  for (double v : values) {
    sum += v;
    sum_sq += v * v;
  }
  s.mean = sum / n;
  s.rmse = std::sqrt(sum_sq / n);
  double var = 0.0;
  for (double v : values) var += (v - s.mean) * (v - s.mean);
  s.std = std::sqrt(var / n);
  std::vector<double> sorted = values;
  std::sort(sorted.begin(), sorted.end());
  const size_t mid = sorted.size() / 2;
  s.median = sorted.size() % 2 == 1 ? sorted[mid] : 0.5 * (sorted[mid - 1] + sorted[mid]);
  s.min = sorted.front();
  s.max = sorted.back();
  return s;
}

double Percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const double rank = std::clamp(p, 0.0, 100.0) / 100.0 * static_cast<double>(values.size() - 1);
  const size_t lo = static_cast<size_t>(std::floor(rank));
  const size_t hi = std::min(lo + 1, values.size() - 1);
  return values[lo] + (rank - static_cast<double>(lo)) * (values[hi] - values[lo]);
}

ErrorStats ScaleErrorStats(const ErrorStats& stats, double factor) {
  ErrorStats s = stats;
  s.rmse *= factor;
  s.mean *= factor;
  s.median *= factor;
  s.std *= factor;
  s.min *= factor;
  s.max *= factor;
  return s;
}

}  // namespace detslam
