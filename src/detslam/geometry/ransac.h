// The RANSAC loop shared by the estimators (PnP, 3-D rigid): minimal samples of distinct indices
// drawn from an injected Rng, adaptive iteration count, best support wins (first one on ties), then
// up to three refits on all inliers that are kept while the support does not shrink. Each
// estimator supplies only its minimal solver, its inlier test and its refit.
#pragma once

#include <algorithm>
#include <utility>
#include <vector>

#include "detslam/core/rng.h"
#include "detslam/geometry/ransac_options.h"

namespace detslam {

template <typename Model>
struct RansacOutcome {
  bool success = false;       // the refit stage was reached and num_inliers >= min_inliers
  Model model{};              // best model after the refits; default when the refits were not run
  std::vector<bool> inliers;  // per datum; all false when the refits were not run
  int num_inliers = 0;
  int iterations = 0;  // hypotheses drawn
};

// k distinct indices in [0, n), drawn one by one from rng (a repeated draw is drawn again).
std::vector<int> SampleDistinctIndices(int n, int k, Rng& rng);

// Indices i with mask[i] set, in increasing order.
std::vector<int> MaskIndices(const std::vector<bool>& mask);

// Runs RANSAC on n data. `sample_size`: size of a minimal sample (also the least n needed, with
// options.min_inliers). `min_refit_support`: the best hypothesis needs at least this many inliers
// for the refit stage to run; otherwise the outcome keeps its defaults (success = false).
// Callbacks:
//   bool fit_minimal(const std::vector<int>& sample, Model* model)      -- false: no hypothesis
//   int classify(const Model& model, std::vector<bool>* inliers)        -- inlier mask and count
//   bool refit(const std::vector<int>& inliers, const Model& start, Model* refined)
template <typename Model, typename FitMinimal, typename Classify, typename Refit>
RansacOutcome<Model> RunRansac(int n, int sample_size, int min_refit_support,
                               const RansacOptions& options, Rng& rng, FitMinimal&& fit_minimal,
                               Classify&& classify, Refit&& refit) {
  constexpr int kMaxRefits = 3;
  RansacOutcome<Model> outcome;
  outcome.inliers.assign(n, false);
  if (n < std::max(sample_size, options.min_inliers)) return outcome;

  int best_count = -1;
  Model best{};
  std::vector<bool> mask;
  int needed = options.max_iterations;
  while (outcome.iterations < needed) {
    ++outcome.iterations;
    const std::vector<int> sample = SampleDistinctIndices(n, sample_size, rng);
    Model hypothesis;
    if (!fit_minimal(sample, &hypothesis)) continue;
    const int count = classify(hypothesis, &mask);
    if (count > best_count) {
      best_count = count;
      best = hypothesis;
      needed = AdaptiveIterations(static_cast<double>(count) / n, sample_size, options.probability,
                                  options.max_iterations);
    }
  }
  if (best_count < min_refit_support) return outcome;

  // Refit on all inliers, starting from the best hypothesis; keep it while the support holds.
  std::vector<bool> best_mask;
  classify(best, &best_mask);
  for (int i = 0; i < kMaxRefits; ++i) {
    Model refined;
    if (!refit(MaskIndices(best_mask), best, &refined)) break;
    const int count = classify(refined, &mask);
    if (count < best_count) break;
    const bool same = (mask == best_mask);
    best = refined;
    best_mask = mask;
    best_count = count;
    if (same) break;
  }
  outcome.model = best;
  outcome.inliers = best_mask;
  outcome.num_inliers = best_count;
  outcome.success = best_count >= options.min_inliers;
  return outcome;
}

// An estimator's public result (fields success, inliers, num_inliers, iterations) from the
// outcome, with the model stored in `model_field`.
template <typename Result, typename Model>
Result ToRansacResult(RansacOutcome<Model> outcome, Model Result::*model_field) {
  Result result;
  result.success = outcome.success;
  result.*model_field = outcome.model;
  result.inliers = std::move(outcome.inliers);
  result.num_inliers = outcome.num_inliers;
  result.iterations = outcome.iterations;
  return result;
}

}  // namespace detslam
