// The Det-SLAM stage's geometric check for movers the segmenter missed (options:
// MoverCheckOptions, DetSlamOptions::geometric). The tracker runs it on each tracked frame
// (tracking/tracker_geometric.cc), because it needs the optimised pose and the map.
//
// After the frame's pose is optimised against the map, every keypoint that was associated with a
// map point or a frame-to-frame point (kept as inlier or rejected by the optimiser) has an image
// reprojection residual (the pixel distance in u, v; depth does not enter), divided by its
// octave's scale so that residuals of all levels compare. Keypoints far above the robust spread
// of the others (FlagGeometricOutliers: median + k * 1.4826 * MAD, with a floor) are mover
// candidates; a candidate counts only with at least `min_cluster` other candidates within
// `radius_px` at the same depth (isolated large residuals are mismatches, not movers).
// Unmatched keypoints next to a confirmed mover at its depth, and keypoints that match the last
// frame's movers, are labelled too. Labelled keypoints never become landmarks or frame-to-frame
// points, so a person the detector missed does not enter the map.
#include "detslam/dynamic/mover_check.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "detslam/features/matcher.h"
#include "detslam/map/projection_search.h"

namespace detslam {
namespace {

bool SameDepth(float a, float b, double ratio) {
  if (a <= 0 || b <= 0) return a <= 0 && b <= 0;  // without depth: position alone decides
  return std::abs(a - b) <= ratio * std::max(a, b);
}

}  // namespace

int LabelMovers(const PinholeCamera& camera, const ScaleInfo& scale,
                const MoverCheckOptions& options, const Frame& frame,
                const std::vector<std::optional<Eigen::Vector3d>>& points, const Frame* last_frame,
                std::vector<KeypointLabel>* labels, std::vector<size_t>* confirmed) {
  const FrameFeatures& f = *frame.features;
  const size_t n = f.size();
  const Rigid3d& pose = *frame.cam_from_world;
  // 1. Residuals of every associated keypoint at the optimised pose.
  std::vector<double> residual(n, -1.0);
  std::vector<Eigen::Vector2d> offset(n, Eigen::Vector2d::Zero());  // observed - projected, pixels
  for (size_t i = 0; i < n; ++i) {
    if (!points[i]) continue;
    const Eigen::Vector3d pc = pose * *points[i];
    if (pc.z() <= 0) continue;
    offset[i] = f.undist[i] - camera.Project(pc);
    residual[i] = offset[i].norm() / scale.scale_factors[static_cast<size_t>(f.keypoints[i].octave)];
  }
  std::vector<KeypointLabel> candidate = *labels;
  const GeometricCheckResult stats = FlagGeometricOutliers(residual, options.threshold, &candidate);

  // 2. Confirm candidates by flagged neighbours at the same depth (candidates of this call only:
  //    keypoints labelled before it, e.g. in a mover region, are not evidence) that moved alike
  //    (options.coherence).
  const double radius = options.radius_px;
  const auto flagged = [&](size_t i) {
    return candidate[i] == KeypointLabel::kGeometric && (*labels)[i] == KeypointLabel::kStatic;
  };
  const auto alike = [&](size_t i, size_t j) {
    if (options.coherence <= 0) return true;
    return (offset[i] - offset[j]).norm() <=
           options.coherence * std::max(offset[i].norm(), offset[j].norm());
  };
  std::vector<size_t> seeds;
  for (size_t i = 0; i < n; ++i) {
    if (!flagged(i)) continue;
    int neighbours = 0;
    for (size_t j : f.grid->FeaturesInArea(f.undist[i].x(), f.undist[i].y(), radius)) {
      if (j != i && flagged(j) && SameDepth(f.depth[i], f.depth[j], options.depth_ratio) &&
          alike(i, j)) {
        ++neighbours;
      }
    }
    if (neighbours >= options.min_cluster) seeds.push_back(i);
  }
  if (confirmed != nullptr) *confirmed = seeds;

  // 3. Keypoints matching the last frame's movers (searched around their last 3-D position) that
  //    moved: a residual against that position above the threshold (a keypoint that stayed put
  //    is static after all).
  std::vector<size_t> carried;
  if (std::isfinite(stats.threshold) && last_frame != nullptr && last_frame->cam_from_world &&
      !last_frame->labels.empty()) {
    const FrameFeatures& last = *last_frame->features;
    const Rigid3d world_from_last = last_frame->cam_from_world->Inverse();
    std::vector<ProjectionCandidate> movers;
    for (size_t i = 0; i < last.size(); ++i) {
      if (last_frame->labels[i] != KeypointLabel::kGeometric || last.depth[i] <= 0) continue;
      ProjectionCandidate c;
      c.position = world_from_last * camera.Unproject(last.undist[i], last.depth[i]);
      c.descriptor = last.Descriptor(i);
      c.predicted_level = last.keypoints[i].octave;
      movers.push_back(c);
    }
    if (!movers.empty()) {
      ProjectionSearchOptions opt;
      opt.window = options.carry_window_px;
      opt.ratio = 0.9;
      opt.max_distance = kThHigh;
      const std::vector<int> m =
          SearchByProjection(camera, scale, f, pose, movers, TakenMask(frame), opt);
      for (size_t c = 0; c < movers.size(); ++c) {
        if (m[c] < 0) continue;
        const size_t kp = static_cast<size_t>(m[c]);
        const Eigen::Vector2d uv = camera.Project(pose * movers[c].position);
        const double r = (uv - f.undist[kp]).norm() /
                         scale.scale_factors[static_cast<size_t>(f.keypoints[kp].octave)];
        if (r > stats.threshold) carried.push_back(kp);
      }
    }
  }

  // 4. Label the seeds and the unmatched keypoints around them at the same depth, and the carried
  //    movers (which do not spread, so that a label never creeps over the static scene).
  int labelled = 0;
  auto label = [&](size_t i) {
    if ((*labels)[i] == KeypointLabel::kStatic) {
      (*labels)[i] = KeypointLabel::kGeometric;
      ++labelled;
    }
  };
  for (size_t i : seeds) {
    label(i);
    for (size_t j : f.grid->FeaturesInArea(f.undist[i].x(), f.undist[i].y(), radius)) {
      if (frame.landmarks[j] == kNoLandmark &&
          SameDepth(f.depth[i], f.depth[j], options.depth_ratio)) {
        label(j);
      }
    }
  }
  const int spread = labelled;
  for (size_t i : carried) label(i);
  spdlog::debug(
      "frame {}: geometric check: {} residuals, median {:.2f}, threshold {:.2f}, {} candidates, {} "
      "seeds, {} with spread, {} carried",
      frame.index, stats.samples, stats.median, stats.threshold, stats.flagged, seeds.size(),
      spread, carried.size());

  return labelled;
}

std::vector<MoverRegion> MoverRegionsOf(const MoverCheckOptions& options, const Frame& frame,
                                        const std::vector<KeypointLabel>& labels) {
  const FrameFeatures& f = *frame.features;
  const size_t n = f.size();
  // Union-find over the labelled keypoints with depth.
  std::vector<size_t> parent(n);
  for (size_t i = 0; i < n; ++i) parent[i] = i;
  const auto root = [&](size_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  const auto mover = [&](size_t i) {
    return labels[i] == KeypointLabel::kGeometric && f.depth[i] > 0;
  };
  for (size_t i = 0; i < n; ++i) {
    if (!mover(i)) continue;
    for (size_t j : f.grid->FeaturesInArea(f.undist[i].x(), f.undist[i].y(), options.radius_px)) {
      if (j != i && mover(j) && SameDepth(f.depth[i], f.depth[j], options.depth_ratio))
        parent[root(j)] = root(i);
    }
  }
  std::map<size_t, std::vector<size_t>> clusters;
  for (size_t i = 0; i < n; ++i) {
    if (mover(i)) clusters[root(i)].push_back(i);
  }
  std::vector<MoverRegion> regions;
  for (const auto& [r, members] : clusters) {
    if (static_cast<int>(members.size()) < options.region_min_keypoints) continue;
    MoverRegion region;
    region.frame = frame.index;
    region.min_u = region.min_v = std::numeric_limits<double>::infinity();
    region.max_u = region.max_v = -std::numeric_limits<double>::infinity();
    std::vector<double> depths;
    for (size_t i : members) {
      region.min_u = std::min(region.min_u, f.undist[i].x());
      region.max_u = std::max(region.max_u, f.undist[i].x());
      region.min_v = std::min(region.min_v, f.undist[i].y());
      region.max_v = std::max(region.max_v, f.undist[i].y());
      depths.push_back(f.depth[i]);
    }
    // The cluster's depths without their tails (a chain of neighbours at the same depth may
    // stretch along a surface), widened by region_depth_ratio.
    std::sort(depths.begin(), depths.end());
    const auto quantile = [&](double q) {
      return depths[static_cast<size_t>(q * static_cast<double>(depths.size() - 1) + 0.5)];
    };
    region.min_depth = quantile(0.1) * (1.0 - options.region_depth_ratio);
    region.max_depth = quantile(0.9) * (1.0 + options.region_depth_ratio);
    regions.push_back(region);
  }
  return regions;
}

int LabelInMoverRegions(const std::vector<MoverRegion>& regions, const MoverCheckOptions& options,
                        const Frame& frame, std::vector<KeypointLabel>* labels) {
  const FrameFeatures& f = *frame.features;
  int labelled = 0;
  for (const MoverRegion& r : regions) {
    const int64_t since = frame.index - r.frame;
    if (since < 1 || since > options.region_frames) continue;
    const double grow = options.radius_px + options.region_growth_px * static_cast<double>(since);
    for (size_t i = 0; i < f.size(); ++i) {
      if ((*labels)[i] != KeypointLabel::kStatic || f.depth[i] < r.min_depth ||
          f.depth[i] > r.max_depth)
        continue;
      const Eigen::Vector2d& p = f.undist[i];
      if (p.x() < r.min_u - grow || p.x() > r.max_u + grow || p.y() < r.min_v - grow ||
          p.y() > r.max_v + grow)
        continue;
      (*labels)[i] = KeypointLabel::kGeometric;
      ++labelled;
    }
  }
  return labelled;
}

}  // namespace detslam
