#include "detslam/tracking/tracker.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <numeric>
#include <set>
#include <sstream>

#include "detslam/core/check.h"
#include "detslam/features/matcher.h"
#include "detslam/geometry/pnp_ransac.h"
#include "detslam/map/projection_search.h"

namespace detslam {

const char* ToString(TrackingState state) {
  switch (state) {
    case TrackingState::kNotInitialized: return "not_initialized";
    case TrackingState::kOk: return "ok";
    case TrackingState::kRecentlyLost: return "recently_lost";
    case TrackingState::kLost: return "lost";
  }
  return "?";
}

bool TrackerOptions::Check(std::string* error) const {
  std::ostringstream os;
  if (min_init_keypoints < 1) os << "min_init_keypoints must be >= 1; ";
  if (!(motion_window > 0) || !(local_map_window > 0)) os << "search windows must be positive; ";
  if (min_pose_inliers < 3) os << "min_pose_inliers must be >= 3; ";
  if (max_frames_between_keyframes < 1) os << "max_frames_between_keyframes must be >= 1; ";
  if (!(ref_ratio > 0 && ref_ratio <= 1)) os << "ref_ratio must be in (0, 1]; ";
  if (error) *error = os.str();
  return os.str().empty();
}

Tracker::Tracker(const PinholeCamera& camera, TrackerOptions options, Map* map)
    : camera_(camera), options_(options), map_(map), rng_(options.seed) {
  std::string error;
  DETSLAM_CHECK_MSG(options_.Check(&error), error);
}

void Tracker::OnKeyFrameErased(KeyFrameId id) {
  if (reference_kf_ == id || !map_->HasKeyFrame(reference_kf_)) {
    reference_kf_ = map_->NumKeyFrames() ? map_->keyframes().rbegin()->first : kNoKeyFrame;
  }
  if (last_keyframe_ == id) last_keyframe_ = reference_kf_;
}

void Tracker::OnLoopClosed(const std::map<KeyFrameId, Rigid3d>& old_poses) {
  if (!last_frame_ || !last_frame_->cam_from_world) return;
  KeyFrameId ref = last_frame_->reference_keyframe;
  if (!map_->HasKeyFrame(ref) || !old_poses.count(ref)) ref = reference_kf_;
  if (!map_->HasKeyFrame(ref) || !old_poses.count(ref)) return;
  last_frame_->cam_from_world = *last_frame_->cam_from_world * old_poses.at(ref).Inverse() * map_->keyframe(ref).cam_from_world;
  BuildTemporaryPoints();
}

TrackingResult Tracker::Track(Frame* frame) {
  TrackingResult result;
  frame->landmarks.assign(frame->size(), kNoLandmark);
  frame->outlier.assign(frame->size(), false);
  frame->labels.assign(frame->size(), KeypointLabel::kStatic);
  temp_matched_.assign(frame->size(), false);
  temp_match_position_.assign(frame->size(), Eigen::Vector3d::Zero());
  dropped_.assign(frame->size(), false);
  dropped_position_.assign(frame->size(), Eigen::Vector3d::Zero());

  if (state_ == TrackingState::kNotInitialized) {
    if (Initialize(frame)) {
      state_ = TrackingState::kOk;
      result.pose_valid = true;
      result.method = "init";
    } else {
      result.method = "waiting for a frame with enough depth";
    }
    result.state = state_;
    if (result.pose_valid) last_frame_ = *frame, BuildTemporaryPoints();
    return result;
  }

  bool ok = false;
  if (state_ == TrackingState::kOk) {
    if (velocity_ && frame->index >= last_reloc_frame_ + 2) {
      ok = TrackWithMotionModel(frame);
      result.method = "motion";
    }
    if (!ok) {
      ok = TrackReferenceKeyFrame(frame);
      result.method = "reference";
    }
  } else {
    ok = Relocalize(frame);
    result.method = "relocalization";
    result.relocalized = ok;
    if (ok) last_reloc_frame_ = frame->index;
  }
  int inliers = 0;
  if (ok) ok = TrackLocalMap(frame, &inliers);
  if (!ok && state_ == TrackingState::kOk) {
    // Last resort before declaring the frame lost: global relocalisation right away.
    ok = Relocalize(frame) && TrackLocalMap(frame, &inliers);
    if (ok) {
      result.method = "relocalization";
      result.relocalized = true;
      last_reloc_frame_ = frame->index;
    }
  }

  if (ok && options_.geometric_check) result.geometric_rejected = ApplyGeometricCheck(frame, &inliers);
  if (ok) {
    state_ = TrackingState::kOk;
    result.pose_valid = true;
    result.num_inliers = inliers;
    result.need_keyframe = NeedNewKeyFrame(*frame, inliers);
    if (last_frame_ && last_frame_->cam_from_world) {
      velocity_ = *frame->cam_from_world * last_frame_->cam_from_world->Inverse();
    }
    frame->reference_keyframe = reference_kf_;
    last_frame_ = *frame;
    BuildTemporaryPoints();
  } else {
    if (state_ == TrackingState::kOk) {
      state_ = TrackingState::kRecentlyLost;
      lost_since_ = frame->stamp;
      spdlog::warn("frame {}: tracking lost, relocalising", frame->index);
    } else if (state_ == TrackingState::kRecentlyLost &&
               AbsDiffSeconds(frame->stamp, lost_since_) > options_.recently_lost_seconds) {
      state_ = TrackingState::kLost;
    }
    frame->cam_from_world.reset();
    velocity_.reset();
    result.method = "lost";
  }
  result.state = state_;
  return result;
}

bool Tracker::Initialize(Frame* frame) {
  const FrameFeatures& f = *frame->features;
  int with_depth = 0;
  for (size_t i = 0; i < f.size(); ++i) with_depth += f.depth[i] > 0 ? 1 : 0;
  if (with_depth < options_.min_init_keypoints) return false;
  frame->cam_from_world = Rigid3d::Identity();
  CreateKeyFrame(frame);
  spdlog::info("map initialised with {} landmarks", map_->NumLandmarks());
  return true;
}

void Tracker::BuildTemporaryPoints() {
  // ORB-SLAM's UpdateLastFrame for RGB-D: points from the last frame's depth for keypoints
  // without a landmark, closest first, all closer than ThDepth and at least 100.
  temporary_points_.assign(last_frame_->size(), std::nullopt);
  const FrameFeatures& f = *last_frame_->features;
  std::vector<std::pair<float, size_t>> by_depth;
  for (size_t i = 0; i < f.size(); ++i) {
    if (f.depth[i] > 0) by_depth.emplace_back(f.depth[i], i);
  }
  std::sort(by_depth.begin(), by_depth.end());
  const Rigid3d world_from_cam = last_frame_->cam_from_world->Inverse();
  int created = 0;
  for (const auto& [d, i] : by_depth) {
    if (!last_frame_->labels.empty() && last_frame_->labels[i] != KeypointLabel::kStatic) continue;
    const bool has_landmark = last_frame_->landmarks[i] != kNoLandmark && map_->HasLandmark(last_frame_->landmarks[i]);
    if (!has_landmark) {
      temporary_points_[i] = world_from_cam * camera_.Unproject(f.undist[i], d);
      ++created;
    }
    if (d > camera_.CloseDepthThreshold() && created > options_.temporary_points_min) break;
  }
}

bool Tracker::TrackWithMotionModel(Frame* frame) {
  frame->cam_from_world = *velocity_ * *last_frame_->cam_from_world;
  const FrameFeatures& last = *last_frame_->features;
  std::vector<ProjectionCandidate> candidates;
  std::vector<size_t> source;
  for (size_t i = 0; i < last.size(); ++i) {
    ProjectionCandidate c;
    const LandmarkId id = last_frame_->landmarks[i];
    if (id != kNoLandmark && !last_frame_->outlier[i] && map_->HasLandmark(id)) {
      c.landmark = id;
      c.position = map_->landmark(id).position;
    } else if (temporary_points_[i]) {
      c.position = *temporary_points_[i];
    } else {
      continue;
    }
    c.descriptor = last.Descriptor(i);
    c.predicted_level = last.keypoints[i].octave;
    c.source_angle = last.keypoints[i].angle;
    candidates.push_back(c);
    source.push_back(i);
  }
  ProjectionSearchOptions opt;
  opt.window = options_.motion_window;
  opt.ratio = 0.9;
  opt.max_distance = kThHigh;
  opt.check_orientation = true;
  auto apply = [&](const std::vector<int>& matches) {
    int n = 0;
    frame->landmarks.assign(frame->size(), kNoLandmark);
    temp_matched_.assign(frame->size(), false);
    for (size_t c = 0; c < candidates.size(); ++c) {
      if (matches[c] < 0) continue;
      const size_t kp = static_cast<size_t>(matches[c]);
      if (candidates[c].landmark != kNoLandmark) {
        frame->landmarks[kp] = candidates[c].landmark;
      } else {
        temp_matched_[kp] = true;
        temp_match_position_[kp] = candidates[c].position;
      }
      ++n;
    }
    return n;
  };
  int n = apply(SearchByProjection(camera_, map_->scale(), *frame->features, *frame->cam_from_world,
                                   candidates, {}, opt));
  if (n < options_.min_motion_matches) {
    opt.window *= 2;
    n = apply(SearchByProjection(camera_, map_->scale(), *frame->features, *frame->cam_from_world,
                                 candidates, {}, opt));
  }
  if (n < options_.min_motion_matches) return false;
  return OptimizeFramePose(frame, true) >= options_.min_pose_inliers;
}

bool Tracker::TrackReferenceKeyFrame(Frame* frame) {
  if (!map_->HasKeyFrame(reference_kf_)) return false;
  const KeyFrame& ref = map_->keyframe(reference_kf_);
  frame->landmarks = MatchKeyFrameLandmarks(ref, *frame->features, 0.7, kThLow);
  const auto matched = std::count_if(frame->landmarks.begin(), frame->landmarks.end(),
                                     [](LandmarkId id) { return id != kNoLandmark; });
  if (matched < 15) return false;
  frame->cam_from_world = last_frame_ ? *last_frame_->cam_from_world : ref.cam_from_world;
  return OptimizeFramePose(frame, false) >= options_.min_pose_inliers;
}

int Tracker::OptimizeFramePose(Frame* frame, bool include_temporary) {
  const FrameFeatures& f = *frame->features;
  std::vector<PoseObservation> obs;
  std::vector<size_t> kp_of_obs;
  for (size_t i = 0; i < f.size(); ++i) {
    Eigen::Vector3d p;
    if (frame->landmarks[i] != kNoLandmark) {
      p = map_->landmark(frame->landmarks[i]).position;
    } else if (include_temporary && temp_matched_[i]) {
      p = temp_match_position_[i];
    } else {
      continue;
    }
    PoseObservation o;
    o.point_world = p;
    o.uv = f.undist[i];
    o.u_right = f.u_right[i];
    o.inv_sigma2 = map_->scale().inv_level_sigma2[static_cast<size_t>(f.keypoints[i].octave)];
    obs.push_back(o);
    kp_of_obs.push_back(i);
  }
  if (obs.size() < 3) return 0;
  const PoseOptimizerResult r = OptimizePose(camera_, *frame->cam_from_world, obs, pose_options_);
  frame->cam_from_world = r.cam_from_world;
  int inliers = 0;
  frame->outlier.assign(f.size(), false);
  for (size_t k = 0; k < obs.size(); ++k) {
    const size_t i = kp_of_obs[k];
    if (r.inliers[k]) {
      ++inliers;
    } else {
      dropped_[i] = true;
      dropped_position_[i] = obs[k].point_world;
      frame->landmarks[i] = kNoLandmark;
      temp_matched_[i] = false;
      frame->outlier[i] = true;
    }
  }
  return inliers;
}

}  // namespace detslam
