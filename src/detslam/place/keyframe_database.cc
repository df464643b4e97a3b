#include "detslam/place/keyframe_database.h"

#include <algorithm>
#include <cmath>

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
  // For L1-normalised non-negative vectors, 1 - 0.5 * |a - b|_1 = sum over common words of
  // min(a_w, b_w): only the shared words' index entries are needed.
  std::vector<Result> results;
  const double norm = L1Norm(bow);
  if (norm <= 0.0) return results;
  std::map<Id, double> scores;
  for (const auto& [word, weight] : bow) {
    auto list = index_.find(word);
    if (list == index_.end()) continue;
    const double q = std::abs(weight) / norm;
    for (const auto& [id, w] : list->second) scores[id] += std::min(q, w);
  }
  for (const auto& [id, score] : scores) {
    if (score > 0.0) results.push_back({id, std::min(score, 1.0)});
  }
  std::sort(results.begin(), results.end(), [](const Result& a, const Result& b) {
    return a.score != b.score ? a.score > b.score : a.id < b.id;
  });
  if (max_results >= 0 && results.size() > static_cast<size_t>(max_results)) {
    results.resize(max_results);
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
