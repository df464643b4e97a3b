#include "detslam/map/map.h"

#include <algorithm>
#include <cmath>

#include "detslam/core/check.h"
#include "detslam/features/orb_extractor.h"

namespace detslam {

int Landmark::PredictScale(double distance, const ScaleInfo& scale) const {
  if (distance <= 0 || max_distance <= 0) return 0;
  const int level =
      static_cast<int>(std::ceil(std::log(max_distance / distance) / scale.log_scale_factor));
  return std::clamp(level, 0, scale.num_levels() - 1);
}

Map::Map(const Map& other)
    : scale_(other.scale_),
      keyframes_(other.keyframes_),
      landmarks_(other.landmarks_),
      place_index_(other.place_index_),
      roots_(other.roots_),
      next_map_id_(other.next_map_id_),
      next_keyframe_id_(other.next_keyframe_id_),
      next_landmark_id_(other.next_landmark_id_) {
  RebuildIndex();
}

Map& Map::operator=(const Map& other) {
  if (this != &other) *this = Map(other);
  return *this;
}

void Map::RebuildIndex() {
  // Sized by the largest id present (ids above it are absent either way), so that a map restored
  // from a file does not allocate for ids it never uses.
  keyframe_at_.assign(keyframes_.empty() ? 0 : static_cast<size_t>(keyframes_.rbegin()->first) + 1,
                      nullptr);
  for (auto& [id, kf] : keyframes_) keyframe_at_[static_cast<size_t>(id)] = &kf;
  landmark_at_.assign(landmarks_.empty() ? 0 : static_cast<size_t>(landmarks_.rbegin()->first) + 1,
                      nullptr);
  for (auto& [id, lm] : landmarks_) landmark_at_[static_cast<size_t>(id)] = &lm;
}

Map Map::Restore(ScaleInfo scale, std::vector<KeyFrame> keyframes, std::vector<Landmark> landmarks,
                 KeyFrameId next_keyframe_id, LandmarkId next_landmark_id) {
  auto fail = [](const std::string& m) { throw InputError(m); };
  Map map(std::move(scale));
  if (next_keyframe_id < 0 || next_landmark_id < 0) fail("negative next id");
  map.next_keyframe_id_ = next_keyframe_id;
  map.next_landmark_id_ = next_landmark_id;
  KeyFrameId last_kf = kNoKeyFrame;
  for (KeyFrame& kf : keyframes) {
    const std::string where = "keyframe " + std::to_string(kf.id) + ": ";
    if (kf.id <= last_kf || kf.id >= next_keyframe_id) fail(where + "id not ascending or too large");
    if (!kf.features) fail(where + "no features");
    if (!kf.labels.empty() && kf.labels.size() != kf.features->size())
      fail(where + "labels do not match the keypoints");
    last_kf = kf.id;
    kf.landmarks.assign(kf.features->size(), kNoLandmark);
    kf.children.clear();
    const KeyFrameId id = kf.id;
    if (!kf.features->bow.empty()) map.place_index_.Insert(id, kf.features->bow);
    map.keyframes_.emplace(id, std::move(kf));
  }
  LandmarkId last_lm = kNoLandmark;
  for (Landmark& lm : landmarks) {
    const std::string where = "map point " + std::to_string(lm.id) + ": ";
    if (lm.id <= last_lm || lm.id >= next_landmark_id) fail(where + "id not ascending or too large");
    last_lm = lm.id;
    for (const auto& [kf_id, idx] : lm.observations) {
      auto it = map.keyframes_.find(kf_id);
      if (it == map.keyframes_.end())
        fail(where + "observed by keyframe " + std::to_string(kf_id) + ", which does not exist");
      if (idx >= it->second.landmarks.size() || it->second.landmarks[idx] != kNoLandmark) {
        fail(where + "keypoint " + std::to_string(idx) + " of keyframe " + std::to_string(kf_id) +
             " is out of range or taken twice");
      }
      it->second.landmarks[idx] = lm.id;
    }
    const LandmarkId id = lm.id;
    map.landmarks_.emplace(id, std::move(lm));
  }
  for (auto& [id, kf] : map.keyframes_) {
    const std::string where = "keyframe " + std::to_string(id) + ": ";
    for (const auto& [other, weight] : kf.covisibility) {
      auto it = map.keyframes_.find(other);
      if (other == id || it == map.keyframes_.end() || weight < 1 ||
          it->second.covisibility.count(id) == 0 || it->second.covisibility.at(id) != weight) {
        fail(where + "covisibility with keyframe " + std::to_string(other) +
             " has no matching reverse edge");
      }
    }
    if (kf.map_id < 0) fail(where + "negative map id");
    if (!map.roots_.count(kf.map_id)) map.roots_[kf.map_id] = id;  // ascending: the lowest id
    map.next_map_id_ = std::max(map.next_map_id_, kf.map_id + 1);
    for (const auto& [other, weight] : kf.covisibility) {
      (void)weight;
      if (map.keyframes_.at(other).map_id != kf.map_id)
        fail(where + "covisibility with keyframe " + std::to_string(other) + " of another map");
    }
    if (kf.parent != kNoKeyFrame) {
      auto it = map.keyframes_.find(kf.parent);
      if (kf.parent == id || it == map.keyframes_.end())
        fail(where + "parent " + std::to_string(kf.parent) + " does not exist");
      if (it->second.map_id != kf.map_id)
        fail(where + "parent " + std::to_string(kf.parent) + " lies in another map");
      if (map.roots_.at(kf.map_id) == id) fail(where + "the first keyframe of a map has a parent");
      it->second.children.insert(id);
    }
  }
  for (const auto& [id, lm] : map.landmarks_) {
    for (const auto& [kf_id, idx] : lm.observations) {
      (void)idx;
      if (map.keyframes_.at(kf_id).map_id !=
          map.keyframes_.at(lm.observations.begin()->first).map_id)
        fail("map point " + std::to_string(id) + ": observed from two maps");
    }
  }
  // Ids are assigned in order, so the next ids lie just past the last ones kept (beyond them only
  // by elements erased at the end); a next id far beyond would make the first new element's index
  // allocation huge (a damaged or crafted file).
  constexpr int64_t kMaxIdGap = int64_t(1) << 24;
  const int64_t last_lm_kept = map.landmarks_.empty() ? -1 : map.landmarks_.rbegin()->first;
  if (next_keyframe_id - (last_kf + 1) > kMaxIdGap ||
      next_landmark_id - (last_lm_kept + 1) > kMaxIdGap)
    fail("next keyframe or map point id implausibly far beyond the last one kept");
  map.RebuildIndex();
  return map;
}

KeyFrameId Map::AddKeyFrame(KeyFrame kf) {
  kf.id = next_keyframe_id_++;
  kf.landmarks.assign(kf.features->size(), kNoLandmark);
  const KeyFrameId id = kf.id;
  DETSLAM_CHECK(kf.map_id >= 0);
  if (!roots_.count(kf.map_id)) {
    DETSLAM_CHECK_MSG(kf.map_id >= next_map_id_, "map " << kf.map_id << " no longer exists");
    roots_[kf.map_id] = id;
    next_map_id_ = kf.map_id + 1;
  }
  if (!kf.features->bow.empty()) place_index_.Insert(id, kf.features->bow);
  KeyFrame* stored = &keyframes_.emplace(id, std::move(kf)).first->second;
  keyframe_at_.resize(static_cast<size_t>(next_keyframe_id_), nullptr);
  keyframe_at_[static_cast<size_t>(id)] = stored;
  return id;
}

LandmarkId Map::AddLandmark(const Eigen::Vector3d& position, KeyFrameId reference) {
  Landmark lm;
  lm.id = next_landmark_id_++;
  lm.position = position;
  lm.reference_keyframe = reference;
  lm.first_keyframe = reference;
  const LandmarkId id = lm.id;
  Landmark* stored = &landmarks_.emplace(id, std::move(lm)).first->second;
  landmark_at_.resize(static_cast<size_t>(next_landmark_id_), nullptr);
  landmark_at_[static_cast<size_t>(id)] = stored;
  return id;
}

KeyFrame& Map::keyframe(KeyFrameId id) {
  KeyFrame* kf = FindKeyFrame(id);
  DETSLAM_CHECK_MSG(kf != nullptr, "no keyframe " << id);
  return *kf;
}
const KeyFrame& Map::keyframe(KeyFrameId id) const {
  const KeyFrame* kf = FindKeyFrame(id);
  DETSLAM_CHECK_MSG(kf != nullptr, "no keyframe " << id);
  return *kf;
}
Landmark& Map::landmark(LandmarkId id) {
  Landmark* lm = FindLandmark(id);
  DETSLAM_CHECK_MSG(lm != nullptr, "no landmark " << id);
  return *lm;
}
const Landmark& Map::landmark(LandmarkId id) const {
  const Landmark* lm = FindLandmark(id);
  DETSLAM_CHECK_MSG(lm != nullptr, "no landmark " << id);
  return *lm;
}

void Map::AddObservation(LandmarkId lm_id, KeyFrameId kf_id, size_t idx) {
  KeyFrame& kf = keyframe(kf_id);
  Landmark& lm = landmark(lm_id);
  DETSLAM_CHECK(idx < kf.landmarks.size());
  DETSLAM_CHECK_MSG(kf.landmarks[idx] == kNoLandmark,
                    "slot " << idx << " of keyframe " << kf_id << " taken");
  if (lm.observations.count(kf_id)) return;  // one observation per keyframe
  lm.observations[kf_id] = idx;
  kf.landmarks[idx] = lm_id;
}

void Map::EraseObservation(LandmarkId lm_id, KeyFrameId kf_id) {
  Landmark& lm = landmark(lm_id);
  auto it = lm.observations.find(kf_id);
  if (it == lm.observations.end()) return;
  KeyFrame& kf = keyframe(kf_id);
  kf.landmarks[it->second] = kNoLandmark;
  lm.observations.erase(it);
  if (lm.observations.empty()) {
    landmark_at_[static_cast<size_t>(lm_id)] = nullptr;
    landmarks_.erase(lm_id);
    return;
  }
  if (lm.reference_keyframe == kf_id) lm.reference_keyframe = lm.observations.begin()->first;
}

void Map::EraseLandmark(LandmarkId lm_id) {
  auto it = landmarks_.find(lm_id);
  if (it == landmarks_.end()) return;
  for (const auto& [kf_id, idx] : it->second.observations)
    keyframe(kf_id).landmarks[idx] = kNoLandmark;
  landmark_at_[static_cast<size_t>(lm_id)] = nullptr;
  landmarks_.erase(it);
}

void Map::ReplaceLandmark(LandmarkId from, LandmarkId into) {
  if (from == into || !HasLandmark(from) || !HasLandmark(into)) return;
  const std::map<KeyFrameId, size_t> obs = landmark(from).observations;
  const int visible = landmark(from).visible, found = landmark(from).found;
  for (const auto& [kf_id, idx] : obs) {
    keyframe(kf_id).landmarks[idx] = kNoLandmark;
    if (!landmark(into).observations.count(kf_id)) AddObservation(into, kf_id, idx);
  }
  landmark_at_[static_cast<size_t>(from)] = nullptr;
  landmarks_.erase(from);
  Landmark& target = landmark(into);
  target.visible += visible;
  target.found += found;
  UpdateLandmarkDescriptor(into);
}

void Map::EraseKeyFrame(KeyFrameId kf_id) {
  if (!HasKeyFrame(kf_id) || IsMapRoot(kf_id)) return;
  KeyFrame& kf = keyframe(kf_id);
  const std::vector<LandmarkId> lms = kf.landmarks;
  for (LandmarkId lm : lms) {
    if (lm != kNoLandmark && HasLandmark(lm)) EraseObservation(lm, kf_id);
  }
  // Reparent children to the parent (simple, keeps a tree rooted at the first keyframe).
  const KeyFrameId parent = kf.parent;
  for (KeyFrameId child : kf.children) {
    if (!HasKeyFrame(child)) continue;
    keyframe(child).parent = parent;
    if (HasKeyFrame(parent)) keyframe(parent).children.insert(child);
  }
  if (HasKeyFrame(parent)) keyframe(parent).children.erase(kf_id);
  for (const auto& [other, w] : kf.covisibility) {
    (void)w;
    if (HasKeyFrame(other)) keyframe(other).covisibility.erase(kf_id);
  }
  place_index_.Erase(kf_id);
  keyframe_at_[static_cast<size_t>(kf_id)] = nullptr;
  keyframes_.erase(kf_id);
}

void Map::UpdateConnections(KeyFrameId kf_id) {
  KeyFrame& kf = keyframe(kf_id);
  std::map<KeyFrameId, int> counts;
  for (LandmarkId lm_id : kf.landmarks) {
    if (lm_id == kNoLandmark) continue;
    for (const auto& [other, idx] : landmark(lm_id).observations) {
      (void)idx;
      if (other != kf_id) ++counts[other];
    }
  }
  for (const auto& [other, w] : kf.covisibility) {
    (void)w;
    if (!counts.count(other) && HasKeyFrame(other)) keyframe(other).covisibility.erase(kf_id);
  }
  kf.covisibility = counts;
  KeyFrameId best = kNoKeyFrame;
  int best_w = 0;
  for (const auto& [other, w] : counts) {
    keyframe(other).covisibility[kf_id] = w;
    if (w > best_w) best_w = w, best = other;
  }
  if (kf.parent == kNoKeyFrame && best != kNoKeyFrame && !IsMapRoot(kf_id)) {
    kf.parent = best;
    keyframe(best).children.insert(kf_id);
  }
}

std::vector<KeyFrameId> Map::BestCovisibles(KeyFrameId kf_id, size_t n, int min_weight) const {
  const KeyFrame& kf = keyframe(kf_id);
  std::vector<std::pair<int, KeyFrameId>> v;
  for (const auto& [other, w] : kf.covisibility) {
    if (w >= min_weight) v.emplace_back(w, other);
  }
  std::sort(v.begin(), v.end(), [](const auto& a, const auto& b) {
    return a.first != b.first ? a.first > b.first : a.second < b.second;
  });
  std::vector<KeyFrameId> out;
  for (size_t i = 0; i < v.size() && i < n; ++i) out.push_back(v[i].second);
  return out;
}

void Map::UpdateLandmarkGeometry(LandmarkId lm_id) {
  Landmark& lm = landmark(lm_id);
  if (lm.observations.empty() || !HasKeyFrame(lm.reference_keyframe)) return;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  for (const auto& [kf_id, idx] : lm.observations) {
    (void)idx;
    const Eigen::Vector3d dir = lm.position - keyframe(kf_id).Center();
    if (dir.norm() > 0) normal += dir.normalized();
  }
  if (normal.norm() > 0) lm.normal = normal.normalized();
  const KeyFrame& ref = keyframe(lm.reference_keyframe);
  const double dist = (lm.position - ref.Center()).norm();
  const int level = ref.features->keypoints[lm.observations.at(ref.id)].octave;
  const double level_scale = scale_.scale_factors[static_cast<size_t>(level)];
  lm.max_distance = dist * level_scale;
  lm.min_distance = lm.max_distance / scale_.scale_factors.back();
}

void Map::UpdateLandmarkDescriptor(LandmarkId lm_id) {
  Landmark& lm = landmark(lm_id);
  std::vector<const uint8_t*> descs;
  for (const auto& [kf_id, idx] : lm.observations)
    descs.push_back(keyframe(kf_id).features->Descriptor(idx));
  if (descs.empty()) return;
  size_t best = 0;
  int best_median = std::numeric_limits<int>::max();
  for (size_t i = 0; i < descs.size(); ++i) {
    std::vector<int> d;
    for (size_t j = 0; j < descs.size(); ++j) d.push_back(DescriptorDistance(descs[i], descs[j]));
    std::sort(d.begin(), d.end());
    const int median = d[(d.size() - 1) / 2];
    if (median < best_median) best_median = median, best = i;
  }
  lm.descriptor = cv::Mat(1, 32, CV_8UC1);
  std::copy(descs[best], descs[best] + 32, lm.descriptor.ptr<uint8_t>());
}

int Map::TrackedLandmarks(KeyFrameId kf_id, int min_obs) const {
  int n = 0;
  for (LandmarkId lm : keyframe(kf_id).landmarks) {
    if (lm != kNoLandmark && static_cast<int>(landmark(lm).observations.size()) >= min_obs) ++n;
  }
  return n;
}

}  // namespace detslam
