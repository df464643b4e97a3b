#include "detslam/mapping/local_mapper.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <map>
#include <set>
#include <sstream>

#include "detslam/core/check.h"
#include "detslam/features/matcher.h"
#include "detslam/optim/bundle_adjustment.h"
#include "detslam/map/projection_search.h"
#include "detslam/mapping/map_bundle.h"

namespace detslam {

bool LocalMapperOptions::Check(std::string* error) const {
  std::ostringstream os;
  if (ba_iterations < 1) os << "ba_iterations must be >= 1; ";
  if (max_local_keyframes < 1) os << "max_local_keyframes must be >= 1; ";
  if (triangulation_neighbours < 1) os << "triangulation_neighbours must be >= 1; ";
  if (!(redundancy > 0 && redundancy <= 1)) os << "redundancy must be in (0, 1]; ";
  if (error) *error = os.str();
  return os.str().empty();
}

LocalMapper::LocalMapper(const PinholeCamera& camera, LocalMapperOptions options, Map* map)
    : camera_(camera), options_(options), map_(map) {
  std::string error;
  DETSLAM_CHECK_MSG(options_.Check(&error), error);
}

LocalMappingSummary LocalMapper::ProcessKeyFrame(KeyFrameId current, std::mutex* map_mutex) {
  std::unique_lock<std::mutex> lock;
  if (map_mutex != nullptr) lock = std::unique_lock<std::mutex>(*map_mutex);
  LocalMappingSummary summary;
  KeyFrame& kf = map_->keyframe(current);
  for (LandmarkId lm : kf.landmarks) {
    if (lm == kNoLandmark) continue;
    Landmark& l = map_->landmark(lm);
    if (l.first_keyframe == current) {
      recent_landmarks_.push_back(lm);
    } else {
      map_->UpdateLandmarkGeometry(lm);
      map_->UpdateLandmarkDescriptor(lm);
    }
  }
  map_->UpdateConnections(current);
  CullLandmarks(current, &summary);
  if (options_.triangulate) TriangulateNewLandmarks(current, &summary);
  if (options_.fuse) FuseWithNeighbours(current, &summary);
  if (options_.local_ba && map_->NumKeyFrames() > 2) LocalBundleAdjustment(current, &summary, &lock);
  if (options_.cull_keyframes) CullKeyFrames(current, &summary);
  return summary;
}

void LocalMapper::CullLandmarks(KeyFrameId current, LocalMappingSummary* summary) {
  std::deque<LandmarkId> keep;
  for (LandmarkId id : recent_landmarks_) {
    if (!map_->HasLandmark(id)) continue;
    const Landmark& lm = map_->landmark(id);
    const KeyFrameId age = current - lm.first_keyframe;
    if (lm.FoundRatio() < options_.min_found_ratio || (age >= 2 && lm.observations.size() < 2)) {
      map_->EraseLandmark(id);
      ++summary->culled_landmarks;
    } else if (age < 3) {
      keep.push_back(id);
    }
  }
  recent_landmarks_ = std::move(keep);
}

void LocalMapper::FuseWithNeighbours(KeyFrameId current, LocalMappingSummary* summary) {
  std::vector<KeyFrameId> targets = map_->BestCovisibles(current, static_cast<size_t>(options_.fuse_neighbours));
  std::set<KeyFrameId> target_set(targets.begin(), targets.end());
  const size_t first_order = targets.size();
  for (size_t k = 0; k < first_order; ++k) {
    for (KeyFrameId n : map_->BestCovisibles(targets[k], 5)) {
      if (n != current && target_set.insert(n).second) targets.push_back(n);
    }
  }
  ProjectionSearchOptions opt;
  opt.window = 3.0;
  opt.ratio = 1.0;
  opt.max_distance = kThLow;
  // Projects `sources` into keyframe `into`; merges or adds observations.
  auto fuse_into = [&](KeyFrameId into, const std::vector<LandmarkId>& sources) {
    std::vector<ProjectionCandidate> cands;
    for (LandmarkId id : sources) {
      if (!map_->HasLandmark(id)) continue;
      const Landmark& lm = map_->landmark(id);
      if (lm.observations.count(into)) continue;
      cands.push_back(CandidateFromLandmark(lm));
    }
    const KeyFrame& kf = map_->keyframe(into);
    const std::vector<int> m = SearchByProjection(camera_, map_->scale(), *kf.features, kf.cam_from_world, cands, {}, opt);
    for (size_t c = 0; c < cands.size(); ++c) {
      if (m[c] < 0 || !map_->HasLandmark(cands[c].landmark)) continue;
      const size_t idx = static_cast<size_t>(m[c]);
      const LandmarkId existing = map_->keyframe(into).landmarks[idx];
      const LandmarkId src = cands[c].landmark;
      if (existing == src || map_->landmark(src).observations.count(into)) continue;
      if (existing != kNoLandmark && map_->HasLandmark(existing)) {
        if (map_->landmark(existing).observations.size() >= map_->landmark(src).observations.size()) {
          map_->ReplaceLandmark(src, existing);
        } else {
          map_->ReplaceLandmark(existing, src);
        }
      } else {
        map_->AddObservation(src, into, idx);
      }
      ++summary->fused;
    }
  };
  for (KeyFrameId t : targets) {
    std::vector<LandmarkId> mine;
    for (LandmarkId id : map_->keyframe(current).landmarks) {
      if (id != kNoLandmark) mine.push_back(id);
    }
    fuse_into(t, mine);
  }
  std::vector<LandmarkId> theirs;
  std::set<LandmarkId> seen;
  for (KeyFrameId t : targets) {
    for (LandmarkId id : map_->keyframe(t).landmarks) {
      if (id != kNoLandmark && seen.insert(id).second) theirs.push_back(id);
    }
  }
  fuse_into(current, theirs);
  for (LandmarkId id : map_->keyframe(current).landmarks) {
    if (id == kNoLandmark) continue;
    map_->UpdateLandmarkDescriptor(id);
    map_->UpdateLandmarkGeometry(id);
  }
  map_->UpdateConnections(current);
}

void LocalMapper::LocalBundleAdjustment(KeyFrameId current, LocalMappingSummary* summary,
                                        std::unique_lock<std::mutex>* lock) {
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<KeyFrameId> local = {current};
  for (KeyFrameId k : map_->BestCovisibles(current, static_cast<size_t>(options_.max_local_keyframes - 1))) local.push_back(k);
  std::set<KeyFrameId> local_set(local.begin(), local.end());
  std::vector<LandmarkId> points;
  std::set<LandmarkId> point_set;
  for (KeyFrameId k : local) {
    for (LandmarkId id : map_->keyframe(k).landmarks) {
      if (id != kNoLandmark && point_set.insert(id).second) points.push_back(id);
    }
  }
  std::map<KeyFrameId, int> fixed_counts;
  for (LandmarkId id : points) {
    for (const auto& [kf, idx] : map_->landmark(id).observations) {
      (void)idx;
      if (!local_set.count(kf)) ++fixed_counts[kf];
    }
  }
  std::vector<std::pair<int, KeyFrameId>> fixed_sorted;
  for (const auto& [kf, n] : fixed_counts) fixed_sorted.emplace_back(-n, kf);
  std::sort(fixed_sorted.begin(), fixed_sorted.end());
  std::vector<KeyFrameId> fixed;
  for (size_t i = 0; i < fixed_sorted.size() && static_cast<int>(i) < options_.max_fixed_keyframes; ++i) fixed.push_back(fixed_sorted[i].second);
  MapBundle bundle = BuildMapBundle(*map_, local, fixed);
  if (bundle.problem.poses.empty()) return;  // no gauge: ORB-SLAM skips local BA then
  BundleOptions bo;
  bo.max_iterations = options_.ba_iterations;
  if (lock->owns_lock()) lock->unlock();  // solve on the copy while tracking goes on
  const BundleSummary s = SolveBundle(camera_, &bundle.problem, bo);
  if (lock->mutex() != nullptr) lock->lock();
  if (!s.usable) return;
  summary->ba_outliers += ApplyMapBundle(bundle, s, map_);
  summary->ba_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

void LocalMapper::CullKeyFrames(KeyFrameId current, LocalMappingSummary* summary) {
  const KeyFrameId origin = map_->first_keyframe();
  for (KeyFrameId k : map_->BestCovisibles(current, 1000)) {
    if (k == origin || k == current || !map_->HasKeyFrame(k)) continue;
    const KeyFrame& kf = map_->keyframe(k);
    int total = 0, redundant = 0;
    for (size_t i = 0; i < kf.size(); ++i) {
      const LandmarkId id = kf.landmarks[i];
      if (id == kNoLandmark) continue;
      const float d = kf.features->depth[i];
      if (d <= 0 || d > camera_.CloseDepthThreshold()) continue;
      ++total;
      const Landmark& lm = map_->landmark(id);
      if (lm.observations.size() <= 3) continue;
      const int level = kf.features->keypoints[i].octave;
      int seen = 0;
      for (const auto& [other, idx] : lm.observations) {
        if (other == k) continue;
        if (map_->keyframe(other).features->keypoints[idx].octave <= level + 1 && ++seen >= 3) break;
      }
      if (seen >= 3) ++redundant;
    }
    if (total > 0 && redundant > options_.redundancy * total) {
      ErasedKeyFrame e;
      e.id = k;
      e.parent = kf.parent;
      if (map_->HasKeyFrame(kf.parent)) e.cam_from_parent = kf.cam_from_world * map_->keyframe(kf.parent).cam_from_world.Inverse();
      map_->EraseKeyFrame(k);
      summary->erased_keyframes.push_back(e);
    }
  }
}

}  // namespace detslam
