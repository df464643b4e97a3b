#include "detslam/features/matcher.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "detslam/core/check.h"
#include "detslam/features/orb_extractor.h"

namespace detslam {

std::vector<cv::DMatch> MatchBruteForce(const std::vector<cv::KeyPoint>& kp_a,
                                        const cv::Mat& desc_a,
                                        const std::vector<cv::KeyPoint>& kp_b,
                                        const cv::Mat& desc_b, const MatchOptions& options) {
  MatchGroup all;
  all.a.resize(kp_a.size());
  all.b.resize(kp_b.size());
  for (size_t i = 0; i < kp_a.size(); ++i) all.a[i] = static_cast<int>(i);
  for (size_t j = 0; j < kp_b.size(); ++j) all.b[j] = static_cast<int>(j);
  return MatchWithinGroups(kp_a, desc_a, kp_b, desc_b, {all}, options);
}

std::vector<cv::DMatch> MatchWithinGroups(const std::vector<cv::KeyPoint>& kp_a,
                                          const cv::Mat& desc_a,
                                          const std::vector<cv::KeyPoint>& kp_b,
                                          const cv::Mat& desc_b,
                                          const std::vector<MatchGroup>& groups,
                                          const MatchOptions& options) {
  DETSLAM_CHECK_MSG(
      desc_a.rows == static_cast<int>(kp_a.size()) && desc_b.rows == static_cast<int>(kp_b.size()),
      "descriptor rows must equal keypoint counts");
  std::vector<cv::DMatch> matches;
  if (kp_a.empty() || kp_b.empty()) return matches;
  DETSLAM_CHECK(desc_a.type() == CV_8UC1 && desc_a.cols == 32 && desc_b.type() == CV_8UC1 &&
                desc_b.cols == 32);

  constexpr int kNone = -1;
  std::vector<int> match_of_b(kp_b.size(), kNone);  // a index currently holding each b
  std::vector<int> best_b_of_a(kp_a.size(), kNone);
  std::vector<int> best_dist_of_a(kp_a.size(), std::numeric_limits<int>::max());
  for (const MatchGroup& group : groups) {
    for (const int i : group.a) {
      const uint8_t* da = desc_a.ptr<uint8_t>(i);
      int best = std::numeric_limits<int>::max(), second = std::numeric_limits<int>::max();
      int best_j = kNone;
      for (const int j : group.b) {
        const int d = DescriptorDistance(da, desc_b.ptr<uint8_t>(j));
        if (d < best) {
          second = best;
          best = d;
          best_j = j;
        } else if (d < second) {
          second = d;
        }
      }
      if (best > options.max_distance) continue;
      if (second != std::numeric_limits<int>::max() &&
          !(static_cast<double>(best) < options.ratio * second)) {
        continue;
      }
      const int holder = match_of_b[best_j];
      if (holder != kNone) {
        if (best_dist_of_a[holder] <= best) continue;  // the earlier (lower-index) one wins ties
        best_b_of_a[holder] = kNone;
      }
      match_of_b[best_j] = i;
      best_b_of_a[i] = best_j;
      best_dist_of_a[i] = best;
    }
  }
  for (size_t i = 0; i < kp_a.size(); ++i) {
    if (best_b_of_a[i] != kNone) {
      matches.emplace_back(static_cast<int>(i), best_b_of_a[i],
                           static_cast<float>(best_dist_of_a[i]));
    }
  }
  if (!options.check_orientation) return matches;

  std::vector<float> differences;
  differences.reserve(matches.size());
  for (const cv::DMatch& m : matches) {
    differences.push_back(kp_a[m.queryIdx].angle - kp_b[m.trainIdx].angle);
  }
  const std::vector<bool> keep = RotationConsistency(differences);
  std::vector<cv::DMatch> consistent;
  for (size_t k = 0; k < matches.size(); ++k) {
    if (keep[k]) consistent.push_back(matches[k]);
  }
  return consistent;
}

std::vector<bool> RotationConsistency(const std::vector<float>& angle_differences_deg, int bins) {
  DETSLAM_CHECK(bins >= 1);
  std::vector<int> bin_of(angle_differences_deg.size());
  std::vector<int> counts(bins, 0);
  const double bin_width = 360.0 / bins;
  for (size_t i = 0; i < angle_differences_deg.size(); ++i) {
    double d = std::fmod(static_cast<double>(angle_differences_deg[i]), 360.0);
    if (d < 0) d += 360.0;
    const int b = std::min(bins - 1, static_cast<int>(d / bin_width));
    bin_of[i] = b;
    ++counts[b];
  }
  // The three most populated bins (stable: lower bin first on ties).
  std::vector<int> order(bins);
  for (int b = 0; b < bins; ++b) order[b] = b;
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return counts[a] > counts[b]; });
  std::vector<bool> bin_kept(bins, false);
  const int max_count = counts[order[0]];
  for (int k = 0; k < std::min(3, bins); ++k) {
    const int c = counts[order[k]];
    if (c == 0) break;
    if (k > 0 && c < 0.1 * max_count) break;
    bin_kept[order[k]] = true;
  }
  std::vector<bool> keep(angle_differences_deg.size());
  for (size_t i = 0; i < keep.size(); ++i) keep[i] = bin_kept[bin_of[i]];
  return keep;
}

}  // namespace detslam
