// The one owner of the map and of its lock. Stages never hold a Map pointer: they borrow the map
// for one step through a scoped access (the lock is held while the access lives), and long
// computations follow one pattern (ComputeOutsideLock): take a snapshot under the lock, solve on
// the snapshot without it while tracking goes on, then write back under the lock what still
// exists.
//
// Whoever holds a write access may also touch state that lives beside the map and is documented
// as guarded by this lock (the tracker's state, the trajectory bookkeeping of SlamSystem).
#pragma once

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

   private:
    friend class MapStore;
    WriteAccess(std::mutex& m, Map* map) : lock_(m), map_(map) {}
    std::unique_lock<std::mutex> lock_;
    Map* map_;
  };
  // Read-only access; excludes writers for its lifetime.
  class ReadAccess {
   public:
    const Map& operator*() const { return *map_; }
    const Map* operator->() const { return map_; }

   private:
    friend class MapStore;
    ReadAccess(std::mutex& m, const Map* map) : lock_(m), map_(map) {}
    std::unique_lock<std::mutex> lock_;
    const Map* map_;
  };

  WriteAccess Write() { return WriteAccess(mutex_, &map_); }
  ReadAccess Read() const { return ReadAccess(mutex_, &map_); }

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
  mutable std::mutex mutex_;
  Map map_;
};

}  // namespace detslam
