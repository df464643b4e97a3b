// Helpers for the map tests only (header-only, not part of the library API).
#pragma once

#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "detslam/map/map.h"

namespace detslam::map_test {

// n keypoints on a row (x = 10 i, y = 20) at 1 m depth, every descriptor byte `fill`.
inline std::shared_ptr<FrameFeatures> RowFeatures(size_t n, uint8_t fill) {
  auto f = std::make_shared<FrameFeatures>();
  for (size_t i = 0; i < n; ++i) {
    f->keypoints.emplace_back(static_cast<float>(10 * i), 20.0f, 31.0f, 0.0f, 1.0f, 0);
    f->undist.emplace_back(10.0 * i, 20.0);
    f->depth.push_back(1.0f);
    f->u_right.push_back(0.0f);
  }
  f->descriptors = cv::Mat(static_cast<int>(n), 32, CV_8UC1, cv::Scalar(fill));
  return f;
}

// A map's keyframes and landmarks as Map::Restore takes them, for tests that damage one part.
using MapParts = std::pair<std::vector<KeyFrame>, std::vector<Landmark>>;

inline MapParts PartsOf(const Map& map) {
  MapParts parts;
  for (const auto& [id, kf] : map.keyframes()) parts.first.push_back(kf);
  for (const auto& [id, lm] : map.landmarks()) parts.second.push_back(lm);
  return parts;
}

// Restores parts with `like`'s scale and next ids.
inline Map RestoreLike(const Map& like, std::vector<KeyFrame> keyframes,
                       std::vector<Landmark> landmarks) {
  return Map::Restore(like.scale(), std::move(keyframes), std::move(landmarks),
                      like.next_keyframe_id(), like.next_landmark_id());
}

}  // namespace detslam::map_test
