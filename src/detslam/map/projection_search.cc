#include "detslam/map/projection_search.h"

#include <cmath>
#include <limits>
#include <unordered_set>

#include "detslam/features/matcher.h"
#include "detslam/features/orb_extractor.h"

namespace detslam {

ProjectionCandidate CandidateFromLandmark(const Landmark& lm) {
  ProjectionCandidate c;
  c.landmark = lm.id;
  c.position = lm.position;
  c.descriptor = lm.descriptor.ptr<uint8_t>();
  c.min_distance = lm.min_distance;
  c.max_distance = lm.max_distance;
  c.normal = lm.normal;
  return c;
}

std::vector<LandmarkId> MatchKeyFrameLandmarks(const KeyFrame& keyframe, const FrameFeatures& frame,
                                               double ratio, int max_distance,
                                               DescriptorSearch search) {
  std::vector<LandmarkId> out(frame.size(), kNoLandmark);
  const FrameFeatures& kf = *keyframe.features;
  std::vector<bool> has_landmark(keyframe.size());
  for (size_t i = 0; i < keyframe.size(); ++i)
    has_landmark[i] = keyframe.landmarks[i] != kNoLandmark;
  std::vector<MatchGroup> groups;
  if (search == DescriptorSearch::kVocabularyNode) {
    groups = SharedNodeGroups(kf.bow_nodes, frame.bow_nodes, has_landmark);
  } else {
    MatchGroup all;
    for (size_t i = 0; i < keyframe.size(); ++i) {
      if (has_landmark[i]) all.a.push_back(static_cast<int>(i));
    }
    for (size_t j = 0; j < frame.size(); ++j) all.b.push_back(static_cast<int>(j));
    groups.push_back(std::move(all));
  }
  MatchOptions mo;
  mo.ratio = ratio;
  mo.max_distance = max_distance;
  for (const cv::DMatch& m : MatchWithinGroups(kf.keypoints, kf.descriptors, frame.keypoints,
                                               frame.descriptors, groups, mo)) {
    out[static_cast<size_t>(m.trainIdx)] = keyframe.landmarks[static_cast<size_t>(m.queryIdx)];
  }
  return out;
}

std::vector<LandmarkId> MatchKeyFramesLandmarks(const std::vector<const KeyFrame*>& keyframes,
                                                const FrameFeatures& frame, double ratio,
                                                int max_distance, DescriptorSearch search) {
  std::vector<LandmarkId> out(frame.size(), kNoLandmark);
  std::unordered_set<LandmarkId> used;
  for (const KeyFrame* keyframe : keyframes) {
    const std::vector<LandmarkId> m =
        MatchKeyFrameLandmarks(*keyframe, frame, ratio, max_distance, search);
    for (size_t i = 0; i < m.size(); ++i) {
      if (out[i] == kNoLandmark && m[i] != kNoLandmark && used.insert(m[i]).second) out[i] = m[i];
    }
  }
  return out;
}

std::vector<bool> TakenMask(const Frame& frame) {
  std::vector<bool> taken(frame.size(), false);
  for (size_t i = 0; i < frame.size(); ++i) taken[i] = frame.landmarks[i] != kNoLandmark;
  return taken;
}

std::vector<int> SearchByProjection(const PinholeCamera& camera, const ScaleInfo& scale,
                                    const FrameFeatures& features, const Rigid3d& cam_from_world,
                                    const std::vector<ProjectionCandidate>& candidates,
                                    const std::vector<bool>& taken,
                                    const ProjectionSearchOptions& options) {
  std::vector<int> result(candidates.size(), -1);
  std::vector<int> best_dist_for_kp(features.size(), std::numeric_limits<int>::max());
  std::vector<int> owner(features.size(), -1);
  const Eigen::Vector3d center = cam_from_world.Inverse().translation();
  std::vector<float> angle_diffs;
  std::vector<size_t> angle_owner;
  for (size_t c = 0; c < candidates.size(); ++c) {
    const ProjectionCandidate& cand = candidates[c];
    const Eigen::Vector3d p_cam = cam_from_world * cand.position;
    if (p_cam.z() <= 0.0) continue;
    const Eigen::Vector2d uv = camera.Project(p_cam);
    if (!camera.InImage(uv)) continue;
    const double dist = (cand.position - center).norm();
    if (cand.max_distance > 0 && (dist < 0.8 * cand.min_distance || dist > 1.2 * cand.max_distance))
      continue;
    if (cand.normal.squaredNorm() > 0 && (cand.position - center).dot(cand.normal) < 0.5 * dist)
      continue;
    int level = cand.predicted_level;
    if (level < 0) {
      level = 0;
      if (cand.max_distance > 0) {
        level = static_cast<int>(
            std::ceil(std::log(cand.max_distance / dist) / scale.log_scale_factor));
        level = std::clamp(level, 0, scale.num_levels() - 1);
      }
    }
    const double radius = options.window * scale.scale_factors[static_cast<size_t>(level)];
    const int min_level = options.level_window_from_prediction ? level - 1 : -1;
    const int max_level =
        options.level_window_from_prediction ? level + (cand.predicted_level >= 0 ? 1 : 0) : -1;
    const std::vector<size_t> near =
        features.grid->FeaturesInArea(uv.x(), uv.y(), radius, min_level, max_level);
    const double ur = uv.x() - camera.bf / p_cam.z();
    int best = std::numeric_limits<int>::max(), second = std::numeric_limits<int>::max();
    int best_level = -1, second_level = -1;
    int best_idx = -1;
    for (size_t idx : near) {
      if (!taken.empty() && taken[idx]) continue;
      if (features.u_right[idx] > 0 && std::abs(ur - features.u_right[idx]) > radius) continue;
      const int d = DescriptorDistance(cand.descriptor, features.Descriptor(idx));
      if (d < best) {
        second = best, second_level = best_level;
        best = d, best_level = features.keypoints[idx].octave, best_idx = static_cast<int>(idx);
      } else if (d < second) {
        second = d, second_level = features.keypoints[idx].octave;
      }
    }
    if (best_idx < 0 || best > options.max_distance) continue;
    if (best_level == second_level && best > options.ratio * second) continue;
    // One-to-one: a keypoint keeps the candidate with the smaller distance.
    const size_t kp = static_cast<size_t>(best_idx);
    if (owner[kp] >= 0) {
      if (best >= best_dist_for_kp[kp]) continue;
      result[static_cast<size_t>(owner[kp])] = -1;
    }
    owner[kp] = static_cast<int>(c);
    best_dist_for_kp[kp] = best;
    result[c] = best_idx;
  }
  if (options.check_orientation) {
    for (size_t c = 0; c < candidates.size(); ++c) {
      if (result[c] < 0 || candidates[c].source_angle < 0) continue;
      angle_diffs.push_back(candidates[c].source_angle -
                            features.keypoints[static_cast<size_t>(result[c])].angle);
      angle_owner.push_back(c);
    }
    const std::vector<bool> keep = RotationConsistency(angle_diffs);
    for (size_t k = 0; k < keep.size(); ++k) {
      if (!keep[k]) result[angle_owner[k]] = -1;
    }
  }
  return result;
}

}  // namespace detslam
