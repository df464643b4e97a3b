// The atlas side of the Map: map roots, keyframes by map, merging one map into another.
#include <algorithm>

#include "detslam/core/check.h"
#include "detslam/map/map.h"

namespace detslam {

bool Map::IsMapRoot(KeyFrameId kf) const {
  const KeyFrame* k = FindKeyFrame(kf);
  if (k == nullptr) return false;
  auto it = roots_.find(k->map_id);
  return it != roots_.end() && it->second == kf;
}

std::vector<KeyFrameId> Map::KeyFramesOfMap(int map_id) const {
  std::vector<KeyFrameId> out;
  for (const auto& [id, kf] : keyframes_) {
    if (kf.map_id == map_id) out.push_back(id);
  }
  return out;
}

size_t Map::NumKeyFramesOfMap(int map_id) const {
  return static_cast<size_t>(std::count_if(keyframes_.begin(), keyframes_.end(),
                                           [map_id](const auto& k) { return k.second.map_id == map_id; }));
}

std::map<KeyFrameId, Rigid3d> Map::MergeMapInto(int from, int into, const Rigid3d& into_from_from,
                                                KeyFrameId seam, KeyFrameId into_seam) {
  DETSLAM_CHECK_MSG(from != into && roots_.count(from) && roots_.count(into),
                    "cannot merge map " << from << " into map " << into);
  DETSLAM_CHECK(MapOf(seam) == from && MapOf(into_seam) == into);
  std::map<KeyFrameId, Rigid3d> before;
  const Rigid3d from_from_into = into_from_from.Inverse();
  for (auto& [id, kf] : keyframes_) {
    if (kf.map_id != from) continue;
    before[id] = kf.cam_from_world;
    kf.cam_from_world = kf.cam_from_world * from_from_into;
    kf.map_id = into;
  }
  for (auto& [id, lm] : landmarks_) {
    if (lm.observations.empty() || !before.count(lm.observations.begin()->first)) continue;
    lm.position = into_from_from * lm.position;
    lm.normal = into_from_from.rotation() * lm.normal;
  }
  // Re-root the moved spanning tree at the seam (reverse the parent links from the seam up to the
  // old root), then hang it below the other map's seam keyframe.
  std::vector<KeyFrameId> path{seam};
  while (keyframe(path.back()).parent != kNoKeyFrame) path.push_back(keyframe(path.back()).parent);
  for (size_t i = path.size() - 1; i > 0; --i) {
    KeyFrame& parent = keyframe(path[i]);
    KeyFrame& child = keyframe(path[i - 1]);
    parent.children.erase(child.id);
    parent.parent = child.id;
    child.children.insert(parent.id);
  }
  keyframe(seam).parent = into_seam;
  keyframe(into_seam).children.insert(seam);
  roots_.erase(from);
  return before;
}

}  // namespace detslam
