#include "detslam/map/place_candidates.h"

#include <algorithm>
#include <unordered_map>

namespace detslam {

std::vector<PlaceCandidate> QueryPlaceCandidates(const Map& map, const BowVector& bow,
                                                 const PlaceQueryOptions& options) {
  std::vector<PlaceCandidate> out;
  KeyFrameDatabase::QueryOptions q;
  q.min_common_ratio = options.min_common_ratio;
  q.min_score = options.min_score;
  if (!options.exclude.empty()) {
    q.exclude = [&options](KeyFrameDatabase::Id id) { return options.exclude.count(id) > 0; };
  }
  const std::vector<KeyFrameDatabase::Result> scored = map.place_index().Query(bow, q);
  if (scored.empty()) return out;
  std::unordered_map<KeyFrameId, double> score_of;
  score_of.reserve(scored.size());
  for (const auto& r : scored) score_of[r.id] = r.score;

  double best_group = 0.0;
  std::vector<PlaceCandidate> groups;
  groups.reserve(scored.size());
  for (const auto& r : scored) {
    if (!map.HasKeyFrame(r.id)) continue;
    PlaceCandidate c{r.id, r.score, r.score};
    for (KeyFrameId n : map.BestCovisibles(r.id, static_cast<size_t>(options.group_size))) {
      auto it = score_of.find(n);
      if (it == score_of.end()) continue;
      c.group_score += it->second;
      if (it->second > c.score || (it->second == c.score && n < c.keyframe)) {
        c.score = it->second;
        c.keyframe = n;
      }
    }
    best_group = std::max(best_group, c.group_score);
    groups.push_back(c);
  }
  const double min_group = options.min_group_ratio * best_group;
  std::stable_sort(groups.begin(), groups.end(),
                   [](const PlaceCandidate& a, const PlaceCandidate& b) {
                     return a.group_score != b.group_score ? a.group_score > b.group_score
                                                           : a.keyframe < b.keyframe;
                   });
  std::set<KeyFrameId> taken;
  for (const PlaceCandidate& c : groups) {
    if (c.group_score <= min_group && c.group_score < best_group) continue;
    if (!taken.insert(c.keyframe).second) continue;
    out.push_back(c);
  }
  return out;
}

std::vector<PlaceCandidate> RelocalizationCandidates(const Map& map, const BowVector& bow) {
  return QueryPlaceCandidates(map, bow, PlaceQueryOptions{});
}

std::vector<PlaceCandidate> LoopCandidates(const Map& map, KeyFrameId kf,
                                           const std::set<KeyFrameId>& exclude) {
  const KeyFrame& query = map.keyframe(kf);
  const BowVector& bow = query.features->bow;
  if (bow.empty()) return {};
  PlaceQueryOptions options;
  options.exclude = exclude;
  options.exclude.insert(kf);
  for (const auto& [other, weight] : query.covisibility) {
    (void)weight;
    options.exclude.insert(other);
  }
  options.min_group_ratio = 0.0;  // every group, best first: the caller takes the best few
  return QueryPlaceCandidates(map, bow, options);
}

}  // namespace detslam
