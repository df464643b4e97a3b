// Place-recognition candidates from the map's bag-of-words index (map.place_index()), with the
// rules ORB-SLAM2/3 use (Mur-Artal and Tardos): keyframes sharing more than 80% of the most words
// any keyframe shares with the query are scored; each one's score is accumulated over its 10 best
// covisible keyframes that are candidates too; groups accumulating more than 75% of the best
// group's score survive, each represented by its best-scoring keyframe.
#pragma once

#include <map>
#include <set>
#include <vector>

#include "detslam/map/map.h"
#include "detslam/place/bow_vector.h"

namespace detslam {

struct PlaceCandidate {
  KeyFrameId keyframe = kNoKeyFrame;  // best-scoring keyframe of its covisibility group
  double score = 0.0;                 // its own score against the query
  double group_score = 0.0;           // the group's accumulated score
};

struct PlaceQueryOptions {
  double min_common_ratio = 0.8;  // words-in-common pre-filter
  double min_score = 0.0;         // candidates scoring below this are left out
  int group_size = 10;            // covisible keyframes accumulated per candidate
  double min_group_ratio = 0.75;  // of the best group's accumulated score
  std::set<KeyFrameId> exclude;   // keyframes never returned nor accumulated
};

// Candidates for `bow` in the map, best group first (ties: lower keyframe id first). Empty when
// the index is empty or nothing shares a word.
std::vector<PlaceCandidate> QueryPlaceCandidates(const Map& map, const BowVector& bow,
                                                 const PlaceQueryOptions& options);

// Relocalisation: candidates for a frame's bag-of-words vector among all keyframes.
std::vector<PlaceCandidate> RelocalizationCandidates(const Map& map, const BowVector& bow);

// Loop detection for keyframe `kf` (ORB-SLAM3's DetectNBestCandidates): keyframes sharing at least
// 80 % of the most words in common, scored, accumulated over their 10 best covisibles, every group
// best first (the caller takes the best few; no minimum score: geometric verification and the
// agreement of several keyframes decide). `kf` and its covisible keyframes are excluded;
// `exclude` adds keyframes to leave out (e.g. recent ones).
std::vector<PlaceCandidate> LoopCandidates(const Map& map, KeyFrameId kf,
                                           const std::set<KeyFrameId>& exclude = {});

}  // namespace detslam
