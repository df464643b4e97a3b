#include "detslam/place/keyframe_database.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace detslam {

void KeyFrameDatabase::Insert(Id id, const BowVector& bow) {
  Erase(id);
  bows_[id] = bow;
  const double norm = L1Norm(bow);
  if (norm <= 0.0) return;
  for (const auto& [word, weight] : bow) {
    if (weight != 0.0) index_[word].emplace_back(id, std::abs(weight) / norm);
  }
}

void KeyFrameDatabase::Erase(Id id) {
  auto it = bows_.find(id);
  if (it == bows_.end()) return;
  for (const auto& entry : it->second) {
    auto list = index_.find(entry.first);
    if (list == index_.end()) continue;
    auto& v = list->second;
    v.erase(std::remove_if(v.begin(), v.end(), [id](const auto& e) { return e.first == id; }),
            v.end());
    if (v.empty()) index_.erase(list);
  }
  bows_.erase(it);
}

std::vector<KeyFrameDatabase::Result> KeyFrameDatabase::Query(const BowVector& bow,
                                                              int max_results) const {
  QueryOptions options;
  options.max_results = max_results;
  return Query(bow, options);
}

std::vector<KeyFrameDatabase::Result> KeyFrameDatabase::Query(const BowVector& bow,
                                                              const QueryOptions& options) const {
  // For L1-normalised non-negative vectors, 1 - 0.5 * |a - b|_1 = sum over common words of
  // min(a_w, b_w): only the shared words' index entries are needed.
  std::vector<Result> results;
  const double norm = L1Norm(bow);
  if (norm <= 0.0) return results;
  std::unordered_map<Id, Result> by_id;
  by_id.reserve(bows_.size());
  for (const auto& [word, weight] : bow) {
    auto list = index_.find(word);
    if (list == index_.end()) continue;
    const double q = std::abs(weight) / norm;
    for (const auto& [id, w] : list->second) {
      Result& r = by_id[id];
      r.id = id;
      r.score += std::min(q, w);
      ++r.common_words;
    }
  }
  int max_common = 0;
  for (const auto& [id, r] : by_id) {
    if (options.exclude && options.exclude(id)) continue;
    max_common = std::max(max_common, r.common_words);
  }
  const double min_common = options.min_common_ratio * max_common;
  for (const auto& [id, r] : by_id) {
    if (options.exclude && options.exclude(id)) continue;
    if (options.min_common_ratio > 0.0 && !(r.common_words > min_common)) continue;
    Result kept = r;
    kept.score = std::min(kept.score, 1.0);
    if (kept.score > 0.0 && kept.score >= options.min_score) results.push_back(kept);
  }
  std::sort(results.begin(), results.end(), [](const Result& a, const Result& b) {
    return a.score != b.score ? a.score > b.score : a.id < b.id;
  });
  if (options.max_results >= 0 && results.size() > static_cast<size_t>(options.max_results)) {
    results.resize(static_cast<size_t>(options.max_results));
  }
  return results;
}

std::vector<KeyFrameDatabase::Id> KeyFrameDatabase::KeyFramesWithWord(int word) const {
  std::vector<Id> ids;
  auto list = index_.find(word);
  if (list == index_.end()) return ids;
  for (const auto& e : list->second) ids.push_back(e.first);
  return ids;
}

}  // namespace detslam
