// Summary statistics of an error series, as the TUM tools (evaluate_ate.py / evaluate_rpe.py
// --verbose) and evo print them: rmse = sqrt(mean(e^2)), mean, median (numpy.median: the mean of
// the two middle values for an even count), std (population standard deviation, numpy.std with
// ddof = 0), min, max, and the count.
#pragma once

#include <cstddef>
#include <vector>

namespace detslam {

struct ErrorStats {
  size_t count = 0;  // number of values; all other fields are 0 when it is 0
  double rmse = 0.0;
  double mean = 0.0;
  double median = 0.0;
  double std = 0.0;
  double min = 0.0;
  double max = 0.0;
};

ErrorStats ComputeErrorStats(const std::vector<double>& values);

// The p-th percentile (0 <= p <= 100) with linear interpolation between the two nearest ranks,
// as numpy.percentile does by default; 0 for no values.
double Percentile(std::vector<double> values, double p);

// Every value field multiplied by `factor` (count unchanged), e.g. to convert units.
ErrorStats ScaleErrorStats(const ErrorStats& stats, double factor);

}  // namespace detslam
