// Tracker: local-map tracking, relocalisation and the keyframe decision.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "detslam/features/matcher.h"
#include "detslam/geometry/pnp_ransac.h"
#include "detslam/map/place_candidates.h"
#include "detslam/map/projection_search.h"
#include "detslam/tracking/tracker.h"

namespace detslam {
namespace {

// Whether the undistorted pixel `uv` lies where `withheld` (CV_8UC1, detected pixels) is set.
bool Withheld(const cv::Mat& withheld, const PinholeCamera& camera, const Eigen::Vector2d& uv) {
  const Eigen::Vector2d d = camera.Distort(uv);
  const int x = static_cast<int>(std::lround(d.x())), y = static_cast<int>(std::lround(d.y()));
  if (x < 0 || y < 0 || x >= withheld.cols || y >= withheld.rows) return false;
  return withheld.at<uint8_t>(y, x) != 0;
}

}  // namespace

void Tracker::UpdateLocalMap(const Map& map, const Frame& frame) {
  // K1: keyframes that observe the frame's landmarks, with the count of shared landmarks.
  std::map<KeyFrameId, int> counts;
  for (size_t i = 0; i < frame.size(); ++i) {
    const LandmarkId id = frame.landmarks[i];
    if (id == kNoLandmark || !map.HasLandmark(id)) continue;
    for (const auto& [kf, idx] : map.landmark(id).observations) {
      (void)idx;
      ++counts[kf];
    }
  }
  local_keyframes_.clear();
  std::set<KeyFrameId> in_local;
  KeyFrameId best = kNoKeyFrame;
  int best_count = 0;
  for (const auto& [kf, n] : counts) {
    local_keyframes_.push_back(kf);
    in_local.insert(kf);
    if (n > best_count) best_count = n, best = kf;
  }
  // K2: the best covisibles of K1, children and parent.
  const size_t k1 = local_keyframes_.size();
  for (size_t k = 0;
       k < k1 && static_cast<int>(local_keyframes_.size()) < options_.max_local_keyframes; ++k) {
    const KeyFrame& kf = map.keyframe(local_keyframes_[k]);
    std::vector<KeyFrameId> more = map.BestCovisibles(kf.id, kLocalMapCovisibles);
    more.insert(more.end(), kf.children.begin(), kf.children.end());
    if (kf.parent != kNoKeyFrame) more.push_back(kf.parent);
    for (KeyFrameId n : more) {
      if (static_cast<int>(local_keyframes_.size()) >= options_.max_local_keyframes) break;
      if (map.HasKeyFrame(n) && in_local.insert(n).second) local_keyframes_.push_back(n);
    }
  }
  if (best != kNoKeyFrame) reference_kf_ = best;
  local_landmarks_.clear();
  local_landmark_set_.Clear();
  for (KeyFrameId kf_id : local_keyframes_) {
    for (LandmarkId id : map.keyframe(kf_id).landmarks) {
      if (id != kNoLandmark && local_landmark_set_.Insert(id)) local_landmarks_.push_back(id);
    }
  }
}

bool Tracker::TrackLocalMap(Map& map, Frame* frame, int* inliers) {
  UpdateLocalMap(map, *frame);
  // Project local landmarks that are not matched yet.
  std::vector<ProjectionCandidate> candidates;
  std::vector<LandmarkId> matched;  // the frame's landmarks, each once
  matched_set_.Clear();
  for (LandmarkId id : frame->landmarks) {
    if (id != kNoLandmark && matched_set_.Insert(id)) matched.push_back(id);
  }
  const Rigid3d& pose = *frame->cam_from_world;
  const Eigen::Vector3d center = pose.Inverse().translation();
  const bool check_withheld = options_.skip_withheld_points && !frame->withheld.empty();
  for (LandmarkId id : local_landmarks_) {
    if (matched_set_.Contains(id)) continue;
    Landmark& lm = map.landmark(id);
    // Frustum check (counts as "visible" for the found ratio).
    Eigen::Vector2d uv;
    if (!InView(lm, *frame, center, check_withheld, &uv)) continue;
    ++lm.visible;
    candidates.push_back(CandidateFromLandmark(lm));
  }
  for (LandmarkId id : matched) ++map.landmark(id).visible;
  ProjectionSearchOptions opt;
  opt.window = options_.local_map_window;
  if (frame->index < last_reloc_frame_ + 2) opt.window = kRelocLocalMapWindow;
  opt.ratio = kLocalMapRatio;
  const std::vector<bool> taken = TakenMask(*frame);
  const std::vector<int> m =
      SearchByProjection(camera_, map.scale(), *frame->features, pose, candidates, taken, opt);
  for (size_t c = 0; c < candidates.size(); ++c) {
    if (m[c] >= 0) frame->landmarks[static_cast<size_t>(m[c])] = candidates[c].landmark;
  }
  scratch_.ClearTemporaryMatches();
  *inliers = OptimizeFramePose(map, frame, false);
  for (size_t i = 0; i < frame->size(); ++i) {
    if (frame->landmarks[i] != kNoLandmark) ++map.landmark(frame->landmarks[i]).found;
  }
  const int needed = frame->index < last_reloc_frame_ + options_.max_frames_between_keyframes
                         ? kRelocalizationInliers
                         : options_.min_local_map_inliers;
  return *inliers >= needed;
}

bool Tracker::InView(const Landmark& lm, const Frame& frame, const Eigen::Vector3d& center,
                     bool check_withheld, Eigen::Vector2d* uv) const {
  const Eigen::Vector3d pc = *frame.cam_from_world * lm.position;
  if (pc.z() <= 0) return false;
  *uv = camera_.Project(pc);
  if (!camera_.InImage(*uv)) return false;
  const double dist = (lm.position - center).norm();
  if (dist < 0.8 * lm.min_distance || dist > 1.2 * lm.max_distance) return false;
  if ((lm.position - center).dot(lm.normal) < 0.5 * dist) return false;
  return !(check_withheld && Withheld(frame.withheld, camera_, *uv));
}

bool Tracker::Relocalize(const Map& map, Frame* frame) {
  // Candidates: with a vocabulary, the keyframes the bag-of-words index proposes (best group
  // first), matched within direct-index nodes; without one, every keyframe, newest first, matched
  // by brute force. The first one that yields a verified pose wins.
  const FrameFeatures& f = *frame->features;
  const bool by_words = !f.bow.empty();
  std::vector<KeyFrameId> kfs;
  if (by_words) {
    for (const PlaceCandidate& c : RelocalizationCandidates(map, f.bow)) kfs.push_back(c.keyframe);
  } else {
    for (auto it = map.keyframes().rbegin(); it != map.keyframes().rend(); ++it)
      kfs.push_back(it->first);
  }
  spdlog::debug("frame {}: {} relocalisation candidates", frame->index, kfs.size());
  for (KeyFrameId kf_id : kfs) {
    const DescriptorSearch search =
        by_words ? DescriptorSearch::kVocabularyNode : DescriptorSearch::kBruteForce;
    std::vector<LandmarkId> matched =
        MatchKeyFrameLandmarks(map.keyframe(kf_id), f, kRelocalizationRatio, kThLow, search);
    if (static_cast<size_t>(std::count_if(matched.begin(), matched.end(), [](LandmarkId id) {
          return id != kNoLandmark;
        })) < kMinRelocalizationMatches) {
      // Too few with the keyframe alone: a frame seen from elsewhere may share more with the
      // keyframe's neighbourhood (as a loop candidate's window is matched).
      std::vector<const KeyFrame*> window{&map.keyframe(kf_id)};
      for (KeyFrameId n : map.BestCovisibles(kf_id, kRelocalizationWindowKeyFrames))
        window.push_back(&map.keyframe(n));
      matched = MatchKeyFramesLandmarks(window, f, kRelocalizationRatio, kThLow, search);
    }
    std::vector<size_t> kp_index;
    std::vector<Eigen::Vector3d> pts;
    std::vector<Eigen::Vector2d> px;
    std::vector<double> sigma2;
    for (size_t i = 0; i < matched.size(); ++i) {
      if (matched[i] == kNoLandmark) continue;
      kp_index.push_back(i);
      pts.push_back(map.landmark(matched[i]).position);
      px.push_back(f.undist[i]);
      sigma2.push_back(map.scale().level_sigma2[static_cast<size_t>(f.keypoints[i].octave)]);
    }
    spdlog::debug("  keyframe {}: {} matches", kf_id, kp_index.size());
    if (kp_index.size() < kMinRelocalizationMatches) continue;
    RansacOptions ro;
    const PnpResult pnp = SolvePnpRansac(camera_, pts, px, sigma2, ro, rng_);
    if (!pnp.success) continue;
    frame->landmarks.assign(frame->size(), kNoLandmark);
    for (size_t k = 0; k < kp_index.size(); ++k) {
      if (pnp.inliers[k]) frame->landmarks[kp_index[k]] = matched[kp_index[k]];
    }
    frame->cam_from_world = pnp.cam_from_world;
    scratch_.ClearTemporaryMatches();
    int inliers = OptimizeFramePose(map, frame, false);
    spdlog::debug("  keyframe {}: PnP {} inliers, optimised {}", kf_id, pnp.num_inliers, inliers);
    if (inliers < kMinRelocalizationPnpInliers) continue;
    const int pnp_inliers = inliers;
    if (inliers < kRelocalizationInliers) {
      // Widen with the keyframe's neighbourhood by projection.
      reference_kf_ = kf_id;
      UpdateLocalMap(map, *frame);
      std::vector<ProjectionCandidate> cands;
      for (LandmarkId id : local_landmarks_) {
        const Landmark& lm = map.landmark(id);
        cands.push_back(CandidateFromLandmark(lm));
      }
      const std::vector<bool> taken = TakenMask(*frame);
      ProjectionSearchOptions po;
      po.window = kRelocalizationWindow;
      po.ratio = kRelocalizationProjectionRatio;
      const std::vector<int> m =
          SearchByProjection(camera_, map.scale(), f, *frame->cam_from_world, cands, taken, po);
      for (size_t c = 0; c < cands.size(); ++c) {
        if (m[c] >= 0) frame->landmarks[static_cast<size_t>(m[c])] = cands[c].landmark;
      }
      inliers = OptimizeFramePose(map, frame, false);
    }
    if (inliers < kRelocalizationInliers) continue;
    // How much of the keyframe's neighbourhood the pose explains: the local-map points in view at
    // it, and the share of them it matched.
    UpdateLocalMap(map, *frame);
    const Eigen::Vector3d center = frame->cam_from_world->Inverse().translation();
    const bool check_withheld = options_.skip_withheld_points && !frame->withheld.empty();
    int in_view = 0;
    Eigen::Vector2d uv;
    for (LandmarkId id : local_landmarks_)
      in_view += InView(map.landmark(id), *frame, center, check_withheld, &uv) ? 1 : 0;
    if (pnp_inliers < kRelocalizationStrongPnpInliers &&
        inliers < kRelocalizationMinViewShare * in_view) {
      spdlog::info(
          "frame {}: relocalisation against keyframe {} rejected as a look-alike place ({} "
          "inliers, {} before the projection search: under {}; {} local-map points in view: under "
          "{:.0f} %)",
          frame->index, kf_id, inliers, pnp_inliers, kRelocalizationStrongPnpInliers, in_view,
          100 * kRelocalizationMinViewShare);
      continue;
    }
    spdlog::info(
        "frame {}: relocalised against keyframe {} ({} inliers; {} before the projection search; "
        "{} local-map points in view)",
        frame->index, kf_id, inliers, pnp_inliers, in_view);
    reference_kf_ = kf_id;  // not UpdateLocalMap's choice: tracking chooses again from here
    return true;
  }
  frame->landmarks.assign(frame->size(), kNoLandmark);
  return false;
}

bool Tracker::NeedNewKeyFrame(const Map& map, const Frame& frame, int inliers,
                              const LocalMappingState& mapping, bool* interrupt) const {
  *interrupt = false;
  // Keyframes of the map being tracked (ORB-SLAM3's KeyFramesInMap, the active map's): in a map
  // started after a loss, counting the atlas's took its first keyframe for a well-mapped one,
  // whose points have 2 or more observations; none had, so the ratio rule never asked for a
  // keyframe and the new map went seconds with one.
  int num_kfs = static_cast<int>(map.NumKeyFrames());
  if (map.map_roots().size() > 1 && map.HasKeyFrame(reference_kf_))
    num_kfs = static_cast<int>(map.NumKeyFramesOfMap(map.MapOf(reference_kf_)));
  const int max_frames = options_.max_frames_between_keyframes;
  if (frame.index < last_reloc_frame_ + max_frames && num_kfs > max_frames) return false;
  // ORB-SLAM counts an RGB-D observation twice; in keyframes its 2 (3) observations are 1 (2).
  const int min_obs = num_kfs <= 2 ? 1 : 2;
  const int ref_matches =
      map.HasKeyFrame(reference_kf_) ? map.TrackedLandmarks(reference_kf_, min_obs) : 0;
  int tracked_close = 0, untracked_close = 0;
  const FrameFeatures& f = *frame.features;
  for (size_t i = 0; i < f.size(); ++i) {
    if (!frame.labels.empty() && frame.labels[i] != KeypointLabel::kStatic) continue;
    if (f.depth[i] > 0 && f.depth[i] < camera_.CloseDepthThreshold()) {
      if (frame.landmarks[i] != kNoLandmark) {
        ++tracked_close;
      } else {
        ++untracked_close;
      }
    }
  }
  // ORB-SLAM3's bNeedToInsertClose; with keyframes_for_withheld also its tracked-close bound
  // divided by the part of the image where keypoints were not withheld (people hiding the near
  // scene leave fewer close points to track, and a keyframe is wanted sooner), but only while
  // local mapping is idle: those extra keyframes must not flood a busy mapping thread (at camera
  // rate they left it mapping in bursts, without fusion or bundle adjustment).
  bool need_close =
      tracked_close < options_.close_tracked_max && untracked_close > options_.close_untracked_min;
  if (!need_close && mapping.idle && options_.keyframes_for_withheld && !frame.withheld.empty() &&
      untracked_close > options_.close_untracked_min) {
    const double visible =
        1.0 - cv::countNonZero(frame.withheld) / static_cast<double>(frame.withheld.total());
    need_close = tracked_close < options_.close_tracked_max / std::max(visible, kMinVisibleForCloseRule);
  }
  const double th_ref = num_kfs < 2 ? kNewKeyFrameRefRatioOneKf : options_.ref_ratio;
  const bool c1a = frame.index >= last_keyframe_frame_ + max_frames;
  const bool c1b = mapping.idle;  // always in sequential runs
  const bool c1c = inliers < kNewKeyFrameLowRatio * ref_matches || need_close;
  const bool c2 = (inliers < th_ref * ref_matches || need_close) && inliers > kMinKeyFrameInliers;
  const bool wanted =
      (keyframe_requested_ && c1a && inliers > kMinKeyFrameInliers) || ((c1a || c1b || c1c) && c2);
  if (!wanted || mapping.idle) return wanted;
  // Mapping is busy: ask it to cut its bundle adjustment short, and queue the keyframe only if
  // few wait (ORB-SLAM3, RGB-D); otherwise a later frame asks again.
  *interrupt = true;
  return mapping.queued < kMaxQueuedKeyFrames;
}

KeyFrameId Tracker::CreateKeyFrame(Map& map, Frame* frame) {
  KeyFrame kf;
  kf.frame_index = frame->index;
  kf.stamp = frame->stamp;
  kf.cam_from_world = *frame->cam_from_world;
  kf.features = frame->features;
  kf.labels = frame->labels;
  kf.map_id = new_map_id_ >= 0 ? new_map_id_ : map.MapOf(reference_kf_);
  const KeyFrameId id = map.AddKeyFrame(std::move(kf));
  for (size_t i = 0; i < frame->size(); ++i) {
    const LandmarkId lm = frame->landmarks[i];
    if (lm != kNoLandmark && map.HasLandmark(lm)) map.AddObservation(lm, id, i);
  }
  CreateLandmarksFromDepth(map, frame, id);
  map.UpdateConnections(id);
  reference_kf_ = id;
  last_keyframe_ = id;
  last_keyframe_frame_ = frame->index;
  keyframe_requested_ = false;
  frame->reference_keyframe = id;
  if (last_frame_ && last_frame_->index == frame->index) {
    last_frame_->landmarks = frame->landmarks;
    last_frame_->reference_keyframe = id;
    BuildTemporaryPoints(map);
  }
  return id;
}

KeyFrameId Tracker::CreateLandmarksFromDepth(Map& map, Frame* frame, KeyFrameId kf_id) {
  const FrameFeatures& f = *frame->features;
  std::vector<std::pair<float, size_t>> by_depth;
  for (size_t i = 0; i < f.size(); ++i) {
    const bool mover = !frame->labels.empty() && frame->labels[i] != KeypointLabel::kStatic;
    if (f.depth[i] > 0 && !mover) by_depth.emplace_back(f.depth[i], i);
  }
  std::sort(by_depth.begin(), by_depth.end());
  const Rigid3d world_from_cam = frame->cam_from_world->Inverse();
  int created = 0;
  for (const auto& [d, i] : by_depth) {
    if (frame->landmarks[i] == kNoLandmark) {
      const LandmarkId lm =
          map.AddLandmark(world_from_cam * camera_.Unproject(f.undist[i], d), kf_id);
      map.AddObservation(lm, kf_id, i);
      map.UpdateLandmarkGeometry(lm);
      map.UpdateLandmarkDescriptor(lm);
      frame->landmarks[i] = lm;
      ++created;
    }
    if (d > camera_.CloseDepthThreshold() && created > options_.keyframe_far_points) break;
  }
  return kf_id;
}

}  // namespace detslam
