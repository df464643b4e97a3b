// Inverted index over keyframes' bag-of-words vectors: word -> (keyframe, weight), so that a
// query scores only the keyframes that share at least one word with it. A query walks the lists
// of its words once, accumulating into dense per-keyframe slots (no per-keyframe allocation), so
// its cost is the number of postings it visits.
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
  // first), each with its ScoreL1 against `bow`; keyframes scoring 0 are left out.
  std::vector<Result> Query(const BowVector& bow, int max_results) const;
  // The same with the filters of `options`.
  std::vector<Result> Query(const BowVector& bow, const QueryOptions& options) const;

  size_t size() const { return bows_.size(); }
  bool Contains(Id id) const { return bows_.count(id) > 0; }
  // Keyframes listed under `word` (in insertion order), for tests and diagnostics.
  std::vector<Id> KeyFramesWithWord(int word) const;

 private:
  // One posting of an inverted list: the keyframe's dense slot and its normalised word weight.
  struct Posting {
    int32_t slot;
    double weight;
  };
  int32_t SlotOf(Id id);  // assigns a slot to a new keyframe (reusing freed ones, newest first)

  std::map<Id, BowVector> bows_;             // every keyframe's vector
  std::vector<std::vector<Posting>> index_;  // word -> postings, in insertion order
  std::unordered_map<Id, int32_t> slot_of_;  // keyframe -> dense slot (accumulator index)
  std::vector<Id> id_of_slot_;               // slot -> keyframe (-1: free)
  std::vector<int32_t> free_slots_;
};

}  // namespace detslam
