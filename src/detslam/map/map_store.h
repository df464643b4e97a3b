// The one owner of the map and of its lock. Stages never hold a Map pointer: they borrow the map
// for one step through a scoped access (the lock is held while the access lives), and long
// computations follow one pattern (ComputeOutsideLock): take a snapshot under the lock, solve on
// the snapshot without it while tracking goes on, then write back under the lock what still
// exists.
//
// Whoever holds a write access may also touch state that lives beside the map and is documented
// as guarded by this lock (the tracker's state, the trajectory bookkeeping of SlamSystem).
//
// Tracking takes the map first (WriteFirst): an access that waits for the lock while tracking
// does lets tracking have it before it, so a frame waits at most for the one step that holds the
// map, not for a stage that releases the lock and takes it again at once (std::mutex is not fair:
// a loop-closing thread verifying candidates one step each could otherwise hold tracking off for
// several steps in a row).
#pragma once

#include <atomic>
#include <condition_variable>
#include <mutex>
#include <optional>
#include <utility>

#include "detslam/map/map.h"

namespace detslam {

class MapStore {
 public:
  explicit MapStore(ScaleInfo scale) : map_(std::move(scale)) {}
  MapStore(const MapStore&) = delete;
  MapStore& operator=(const MapStore&) = delete;

  // Exclusive access for one step; the lock is released when the access is destroyed.
  class WriteAccess {
   public:
    Map& operator*() const { return *map_; }
    Map* operator->() const { return map_; }

    ~WriteAccess() {
      if (!first_) return;
      lock_.unlock();
      first_->notify_all();  // the accesses that let this one go first
    }
    WriteAccess(const WriteAccess&) = delete;
    WriteAccess& operator=(const WriteAccess&) = delete;

   private:
    friend class MapStore;
    WriteAccess(std::unique_lock<std::mutex> lock, Map* map, std::condition_variable* first)
        : lock_(std::move(lock)), map_(map), first_(first) {}
    std::unique_lock<std::mutex> lock_;
    Map* map_;
    std::condition_variable* first_;  // set for WriteFirst
  };
  // Read-only access; excludes writers for its lifetime.
  class ReadAccess {
   public:
    const Map& operator*() const { return *map_; }
    const Map* operator->() const { return map_; }

   private:
    friend class MapStore;
    ReadAccess(std::unique_lock<std::mutex> lock, const Map* map)
        : lock_(std::move(lock)), map_(map) {}
    std::unique_lock<std::mutex> lock_;
    const Map* map_;
  };

  WriteAccess Write() { return WriteAccess(LockAfterFirst(), &map_, nullptr); }
  ReadAccess Read() const { return ReadAccess(LockAfterFirst(), &map_); }
  // Exclusive access ahead of the Write and Read accesses waiting for the lock (tracking's).
  WriteAccess WriteFirst() {
    ++first_waiting_;
    std::unique_lock<std::mutex> lock(mutex_);
    --first_waiting_;
    return WriteAccess(std::move(lock), &map_, &first_done_);
  }

  // The snapshot-solve-apply pattern. `snapshot(const Map&) -> std::optional<S>` runs under the
  // lock (nullopt: nothing to do); `solve(S&) -> R` runs without it; `apply(Map&, const S&,
  // const R&)` runs under the lock again and must skip what was removed meanwhile. Returns
  // whether anything was solved.
  template <typename SnapshotFn, typename SolveFn, typename ApplyFn>
  bool ComputeOutsideLock(SnapshotFn snapshot, SolveFn solve, ApplyFn apply) {
    auto taken = [&] {
      const ReadAccess map = Read();
      return snapshot(*map);
    }();
    if (!taken) return false;
    const auto result = solve(*taken);
    const WriteAccess map = Write();
    apply(*map, *taken, result);
    return true;
  }

 private:
  std::unique_lock<std::mutex> LockAfterFirst() const {
    std::unique_lock<std::mutex> lock(mutex_);
    first_done_.wait(lock, [this] { return first_waiting_.load() == 0; });
    return lock;
  }

  mutable std::mutex mutex_;
  mutable std::condition_variable first_done_;
  mutable std::atomic<int> first_waiting_{0};
  Map map_;
};

}  // namespace detslam
