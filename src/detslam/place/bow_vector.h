// Bag-of-words vectors and the L1 similarity score between them (Galvez-Lopez and Tardos 2012).
#pragma once

#include <map>
#include <vector>

#include "detslam/features/matcher.h"

namespace detslam {

// Sparse word id -> weight (tf * idf), L1-normalised by Vocabulary::Transform. Ordered by word id.
using BowVector = std::map<int, double>;

// The "direct index" of one image: vocabulary node id -> indices (rows of the descriptor matrix,
// ascending) of the descriptors that pass through that node. Used to restrict descriptor matching
// between two images to descriptors under the same node.
using FeatureVector = std::map<int, std::vector<int>>;

// L1 score s = 1 - 0.5 * || a/|a| - b/|b| ||_1, in [0, 1]; identical (up to scale) vectors score 1,
// vectors without a common word score 0. An empty (or all-zero) vector scores 0 with anything.
double ScoreL1(const BowVector& a, const BowVector& b);

// The nodes two direct indexes share, in node order, as match groups (a: indices of `a`'s
// descriptors under the node, b: those of `b`), for MatchWithinGroups. `keep_a` (may be empty:
// all) leaves out a's descriptors whose flag is false; groups left without a or b are dropped.
std::vector<MatchGroup> SharedNodeGroups(const FeatureVector& a, const FeatureVector& b,
                                         const std::vector<bool>& keep_a = {});

// Sum of |weights|.
double L1Norm(const BowVector& v);

// Walks two sequences of (key, value) pairs, both sorted by ascending key, and calls
// both(x, y) for every key they share, in key order; stops at the end of either.
template <typename A, typename B, typename Both>
void ForEachCommonKey(const A& a, const B& b, Both both) {
  auto ia = a.begin();
  auto ib = b.begin();
  while (ia != a.end() && ib != b.end()) {
    if (ia->first < ib->first) {
      ++ia;
    } else if (ib->first < ia->first) {
      ++ib;
    } else {
      both(*ia, *ib);
      ++ia;
      ++ib;
    }
  }
}

}  // namespace detslam
