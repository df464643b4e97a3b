#include "detslam/place/keyframe_database.h"

#include <algorithm>
#include <cmath>

namespace detslam {

int32_t KeyFrameDatabase::SlotOf(Id id) {
  int32_t slot;
  if (!free_slots_.empty()) {
    slot = free_slots_.back();
    free_slots_.pop_back();
    id_of_slot_[static_cast<size_t>(slot)] = id;
  } else {
    slot = static_cast<int32_t>(id_of_slot_.size());
    id_of_slot_.push_back(id);
    bow_of_slot_.emplace_back();
  }
  slot_of_[id] = slot;
  return slot;
}

void KeyFrameDatabase::Insert(Id id, const BowVector& bow) {
  Erase(id);
  const int32_t slot = SlotOf(id);
  FlatBow& flat = bow_of_slot_[static_cast<size_t>(slot)];
  flat.clear();
  const double norm = L1Norm(bow);
  if (norm <= 0.0) return;
  for (const auto& [word, weight] : bow) {
    if (weight == 0.0 || word < 0) continue;
    if (static_cast<size_t>(word) >= index_.size()) index_.resize(static_cast<size_t>(word) + 1);
    index_[static_cast<size_t>(word)].push_back(slot);
    flat.emplace_back(word, std::abs(weight) / norm);
  }
}

void KeyFrameDatabase::Erase(Id id) {
  auto it = slot_of_.find(id);
  if (it == slot_of_.end()) return;
  const int32_t slot = it->second;
  FlatBow& flat = bow_of_slot_[static_cast<size_t>(slot)];
  for (const auto& entry : flat) {
    auto& v = index_[static_cast<size_t>(entry.first)];
    v.erase(std::remove(v.begin(), v.end(), slot), v.end());
  }
  flat.clear();
  flat.shrink_to_fit();
  slot_of_.erase(it);
  id_of_slot_[static_cast<size_t>(slot)] = -1;
  free_slots_.push_back(slot);
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
  // min(a_w, b_w): only the shared words matter.
  std::vector<Result> results;
  const double norm = L1Norm(bow);
  if (norm <= 0.0) return results;
  // Pass 1: shared words per slot, over the postings of the query's words.
  std::vector<int> common(id_of_slot_.size(), 0);
  for (const auto& [word, weight] : bow) {
    (void)weight;
    if (word < 0 || static_cast<size_t>(word) >= index_.size()) continue;
    for (const int32_t slot : index_[static_cast<size_t>(word)]) ++common[static_cast<size_t>(slot)];
  }
  int max_common = 0;
  for (size_t s = 0; s < common.size(); ++s) {
    if (common[s] == 0 || (options.exclude && options.exclude(id_of_slot_[s]))) {
      common[s] = 0;  // excluded slots take no further part
      continue;
    }
    max_common = std::max(max_common, common[s]);
  }
  // Pass 2: the score of each slot that passes the filter, merging its vector with the query's
  // (both by ascending word; the same sum, in the same order, as accumulating over postings).
  std::vector<std::pair<int, double>> query;
  query.reserve(bow.size());
  for (const auto& [word, weight] : bow) {
    if (word >= 0 && static_cast<size_t>(word) < index_.size())
      query.emplace_back(word, std::abs(weight) / norm);
  }
  const double min_common = options.min_common_ratio * max_common;
  for (size_t s = 0; s < common.size(); ++s) {
    if (common[s] == 0) continue;
    if (options.min_common_ratio > 0.0 && !(common[s] > min_common)) continue;
    double score = 0.0;
    ForEachCommonKey(query, bow_of_slot_[s],
                     [&](const auto& q, const auto& k) { score += std::min(q.second, k.second); });
    const double clipped = std::min(score, 1.0);
    if (clipped > 0.0 && clipped >= options.min_score) {
      results.push_back({id_of_slot_[s], clipped, common[s]});
    }
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
  if (word < 0 || static_cast<size_t>(word) >= index_.size()) return ids;
  for (const int32_t slot : index_[static_cast<size_t>(word)]) {
    ids.push_back(id_of_slot_[static_cast<size_t>(slot)]);
  }
  return ids;
}

}  // namespace detslam
