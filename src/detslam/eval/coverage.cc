#include "detslam/eval/coverage.h"

#include <algorithm>
#include <utility>

#include "detslam/core/stats.h"

namespace detslam {

CoverageResult ComputeCoverage(const std::vector<Timestamp>& frames,
                               const std::vector<Timestamp>& gt,
                               const std::vector<Timestamp>& est,
                               const AssociationOptions& options) {
  CoverageResult out;
  std::vector<bool> has_gt(frames.size(), false), has_est(frames.size(), false);
  for (const auto& [g, f] : AssociateTimestamps(gt, frames, options)) {
    (void)g;
    has_gt[f] = true;
  }
  AssociationOptions est_options = options;
  est_options.offset_s = 0.0;
  for (const auto& [f, e] : AssociateTimestamps(frames, est, est_options)) {
    (void)e;
    has_est[f] = true;
  }
  std::vector<std::pair<Timestamp, bool>> rows;
  for (size_t f = 0; f < frames.size(); ++f) {
    if (has_gt[f]) rows.emplace_back(frames[f], has_est[f]);
  }
  std::sort(rows.begin(), rows.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& [stamp, tracked] : rows) {
    out.frame_stamps.push_back(stamp);
    out.tracked.push_back(tracked);
    if (tracked) ++out.frames_tracked;
  }
  out.frames_with_gt = rows.size();
  if (rows.empty()) return out;
  out.fraction = static_cast<double>(out.frames_tracked) / static_cast<double>(out.frames_with_gt);

  std::vector<double> intervals;
  for (size_t k = 1; k < rows.size(); ++k) {
    intervals.push_back(static_cast<double>(rows[k].first.ns - rows[k - 1].first.ns) * 1e-9);
  }
  const double frame_interval_s = ComputeErrorStats(intervals).median;
  size_t k = 0;
  while (k < rows.size()) {
    if (rows[k].second) {
      ++k;
      continue;
    }
    size_t end = k;
    while (end + 1 < rows.size() && !rows[end + 1].second) ++end;
    const size_t count = end - k + 1;
    const double duration =
        static_cast<double>(rows[end].first.ns - rows[k].first.ns) * 1e-9 + frame_interval_s;
    if (out.longest_untracked_frames == 0 || duration > out.longest_untracked_s) {
      out.longest_untracked_frames = count;
      out.longest_untracked_s = duration;
      out.longest_untracked_start = rows[k].first;
    }
    k = end + 1;
  }
  return out;
}

}  // namespace detslam
