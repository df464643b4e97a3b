// Inverted index over keyframes' bag-of-words vectors: word -> (keyframe id, weight), so that a
// query scores only the keyframes that share at least one word with it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <utility>
#include <vector>

#include "detslam/place/bow_vector.h"

namespace detslam {

class KeyFrameDatabase {
 public:
  using Id = int64_t;  // a keyframe id (map/frame.h's KeyFrameId)

  struct Result {
    Id id = -1;
    double score = 0.0;    // ScoreL1 with the query (as sum of shared min weights), in (0, 1]
    int common_words = 0;  // words shared with the query
  };

  struct QueryOptions {
    int max_results = -1;  // keep at most this many (best first); < 0: all
    // Keep only keyframes sharing more than this fraction of the most words any candidate shares
    // with the query (ORB-SLAM's 0.8 pre-filter); 0: all.
    double min_common_ratio = 0.0;
    double min_score = 0.0;  // keep only scores >= this (and > 0)
    // Keyframes to leave out before anything else (e.g. the query keyframe's neighbours); may be
    // empty.
    std::function<bool(Id)> exclude;
  };

  // Adds (or replaces) keyframe `id` with its BowVector (weights are taken as |w| / |bow|_1).
  void Insert(Id id, const BowVector& bow);
  // Removes keyframe `id`; unknown ids are ignored.
  void Erase(Id id);
  // The at most `max_results` keyframes sharing a word with `bow`, best score first (ties: lower id
  // first), each with its ScoreL1 against `bow`; keyframes scoring 0 are left out.
  std::vector<Result> Query(const BowVector& bow, int max_results) const;
  // The same with the filters of `options`.
  std::vector<Result> Query(const BowVector& bow, const QueryOptions& options) const;

  size_t size() const { return bows_.size(); }
  bool Contains(Id id) const { return bows_.count(id) > 0; }
  // Keyframes listed under `word` (in insertion order), for tests and diagnostics.
  std::vector<Id> KeyFramesWithWord(int word) const;

 private:
  std::map<Id, BowVector> bows_;                             // every keyframe's vector
  std::map<int, std::vector<std::pair<Id, double>>> index_;  // word -> (keyframe, weight)
};

}  // namespace detslam
