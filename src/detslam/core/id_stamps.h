// A set of non-negative integer ids (landmark or keyframe ids, which are handed out in ascending
// order) that is emptied in O(1): each id carries the round in which it was last inserted. Built
// for per-frame bookkeeping over tens of thousands of ids (the tracker's local map), where a
// std::set costs an allocation and a tree walk per id every frame.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "detslam/core/check.h"

namespace detslam {

class IdStamps {
 public:
  // Empties the set.
  void Clear() {
    if (++round_ == 0) {  // the counter wrapped: forget every old stamp
      std::fill(stamp_.begin(), stamp_.end(), 0u);
      round_ = 1;
    }
  }
  // Inserts `id`; true if it was not in the set yet.
  bool Insert(int64_t id) {
    DETSLAM_CHECK(id >= 0);
    const auto i = static_cast<size_t>(id);
    if (i >= stamp_.size()) stamp_.resize(std::max(i + 1, 2 * stamp_.size()), 0u);
    if (stamp_[i] == round_) return false;
    stamp_[i] = round_;
    return true;
  }
  bool Contains(int64_t id) const {
    const auto i = static_cast<size_t>(id);
    return id >= 0 && i < stamp_.size() && stamp_[i] == round_;
  }

 private:
  std::vector<uint32_t> stamp_;
  uint32_t round_ = 1;  // stamps start at 0: nothing is in the set
};

}  // namespace detslam
