// Inverted index over keyframes' bag-of-words vectors: word -> (keyframe id, weight), so that a
// query scores only the keyframes that share at least one word with it.
#pragma once

#include <cstddef>
#include <cstdint>
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
    double score = 0.0;  // ScoreL1 with the query (as sum of shared min weights), in (0, 1]
  };

  // Adds (or replaces) keyframe `id` with its BowVector (weights are taken as |w| / |bow|_1).
  void Insert(Id id, const BowVector& bow);
  // Removes keyframe `id`; unknown ids are ignored.
  void Erase(Id id);
  // The at most `max_results` keyframes sharing a word with `bow`, best score first (ties: lower id
  // first), each with its ScoreL1 against `bow`; keyframes scoring 0 are left out.
  std::vector<Result> Query(const BowVector& bow, int max_results) const;

  size_t size() const { return bows_.size(); }
  bool Contains(Id id) const { return bows_.count(id) > 0; }
  // Keyframes listed under `word` (in insertion order), for tests and diagnostics.
  std::vector<Id> KeyFramesWithWord(int word) const;

 private:
  std::map<Id, BowVector> bows_;                             // every keyframe's vector
  std::map<int, std::vector<std::pair<Id, double>>> index_;  // word -> (keyframe, weight)
};

}  // namespace detslam
