// Inverted index over keyframes' bag-of-words vectors: word -> keyframes, so that a query scores
// only the keyframes that share at least one word with it. A query walks the lists of its words
// once, counting shared words into dense per-keyframe slots (4 bytes per posting visited), then
// scores only the keyframes that pass the shared-words filter, each by merging its stored
// (normalised, flat) vector with the query's. With ORB-SLAM's 0.8 filter few keyframes are scored.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <unordered_map>
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
  // first), each with its ScoreL1 against `bow`; keyframes scoring 0 are left out. (Scores every
  // keyframe sharing a word: on a large map prefer the options with min_common_ratio.)
  std::vector<Result> Query(const BowVector& bow, int max_results) const;
  // The same with the filters of `options`.
  std::vector<Result> Query(const BowVector& bow, const QueryOptions& options) const;

  size_t size() const { return slot_of_.size(); }
  bool Contains(Id id) const { return slot_of_.count(id) > 0; }
  // Keyframes listed under `word` (in insertion order), for tests and diagnostics.
  std::vector<Id> KeyFramesWithWord(int word) const;

 private:
  // A keyframe's vector as stored: (word, |w| / |bow|_1) by ascending word, zero weights left out.
  using FlatBow = std::vector<std::pair<int, double>>;
  int32_t SlotOf(Id id);  // assigns a slot to a new keyframe (reusing freed ones, newest first)
  std::vector<std::vector<int32_t>> index_;  // word -> slots of the keyframes with it, in insertion order
  std::unordered_map<Id, int32_t> slot_of_;  // keyframe -> dense slot (accumulator index)
  std::vector<Id> id_of_slot_;               // slot -> keyframe (-1: free)
  std::vector<FlatBow> bow_of_slot_;         // slot -> its keyframe's vector
  std::vector<int32_t> free_slots_;
};

}  // namespace detslam
