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

#include <cmath>

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
                std::vector<KeypointLabel>* labels) {
  const FrameFeatures& f = *frame.features;
  const size_t n = f.size();
  const Rigid3d& pose = *frame.cam_from_world;
  // 1. Residuals of every associated keypoint at the optimised pose.
  std::vector<double> residual(n, -1.0);
  for (size_t i = 0; i < n; ++i) {
    if (!points[i]) continue;
    const Eigen::Vector3d pc = pose * *points[i];
    if (pc.z() <= 0) continue;
    const Eigen::Vector2d uv = camera.Project(pc);
    residual[i] =
        (uv - f.undist[i]).norm() / scale.scale_factors[static_cast<size_t>(f.keypoints[i].octave)];
  }
  std::vector<KeypointLabel> candidate = *labels;
  const GeometricCheckResult stats = FlagGeometricOutliers(residual, options.threshold, &candidate);

  // 2. Confirm candidates by flagged neighbours at the same depth.
  const double radius = options.radius_px;
  std::vector<size_t> seeds;
  for (size_t i = 0; i < n; ++i) {
    if (candidate[i] != KeypointLabel::kGeometric) continue;
    int neighbours = 0;
    for (size_t j : f.grid->FeaturesInArea(f.undist[i].x(), f.undist[i].y(), radius)) {
      if (j != i && candidate[j] == KeypointLabel::kGeometric &&
          SameDepth(f.depth[i], f.depth[j], options.depth_ratio)) {
        ++neighbours;
      }
    }
    if (neighbours >= options.min_cluster) seeds.push_back(i);
  }

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

}  // namespace detslam
