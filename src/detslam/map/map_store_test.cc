#include "detslam/map/map_store.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <stdexcept>
#include <thread>

namespace detslam {
namespace {

ScaleInfo TwoLevels() { return ScaleInfo::Geometric(1.2, 2); }

TEST(MapStore, WriteAccessChangesTheMapAndReadAccessSeesIt) {
  MapStore store(TwoLevels());
  store.Write()->AddLandmark(Eigen::Vector3d(1, 2, 3), kNoKeyFrame);
  const MapStore::ReadAccess map = store.Read();
  ASSERT_EQ(map->NumLandmarks(), 1u);
  EXPECT_EQ(map->landmarks().begin()->second.position, Eigen::Vector3d(1, 2, 3));
}

TEST(MapStore, ComputeOutsideLockSkipsWhenTheSnapshotIsEmpty) {
  MapStore store(TwoLevels());
  bool solved = false, applied = false;
  const bool ran =
      store.ComputeOutsideLock([](const Map&) -> std::optional<int> { return std::nullopt; },
                               [&](int&) {
                                 solved = true;
                                 return 0;
                               },
                               [&](Map&, const int&, const int&) { applied = true; });
  EXPECT_FALSE(ran);
  EXPECT_FALSE(solved);
  EXPECT_FALSE(applied);
}

// The solve runs without the lock: another thread writes the map meanwhile, and the apply step
// sees that write (and must skip what was removed).
TEST(MapStore, SolveRunsWithoutTheLockAndApplySkipsWhatWasRemoved) {
  MapStore store(TwoLevels());
  const LandmarkId kept = store.Write()->AddLandmark(Eigen::Vector3d(0, 0, 1), kNoKeyFrame);
  const LandmarkId removed = store.Write()->AddLandmark(Eigen::Vector3d(0, 0, 2), kNoKeyFrame);
  std::mutex m;
  std::condition_variable cv;
  bool writer_done = false;
  std::thread writer;
  const bool ran = store.ComputeOutsideLock(
      [&](const Map& map) -> std::optional<std::vector<LandmarkId>> {
        std::vector<LandmarkId> ids;
        for (const auto& [id, lm] : map.landmarks()) ids.push_back(id);
        return ids;
      },
      [&](std::vector<LandmarkId>& ids) {
        // A write while solving would deadlock if the store were still locked.
        writer = std::thread([&] {
          store.Write()->EraseLandmark(removed);
          const std::lock_guard<std::mutex> lock(m);
          writer_done = true;
          cv.notify_one();
        });
        std::unique_lock<std::mutex> lock(m);
        cv.wait(lock, [&] { return writer_done; });
        return static_cast<int>(ids.size());
      },
      [&](Map& map, const std::vector<LandmarkId>& ids, const int& n) {
        EXPECT_EQ(n, 2);
        for (LandmarkId id : ids) {
          if (map.HasLandmark(id)) map.landmark(id).position.x() = 5;
        }
      });
  writer.join();
  EXPECT_TRUE(ran);
  const MapStore::ReadAccess map = store.Read();
  EXPECT_FALSE(map->HasLandmark(removed));
  ASSERT_TRUE(map->HasLandmark(kept));
  EXPECT_EQ(map->landmark(kept).position.x(), 5);
}

// A stage that takes the map again and again, one step at a time, lets tracking's WriteFirst in
// after at most the step it is in and one that had already passed the check: std::mutex alone
// promises nothing (the thread that unlocks usually takes the lock again at once).
TEST(MapStore, WriteFirstGoesBeforeAStageThatTakesTheMapAgainAndAgain) {
  MapStore store(TwoLevels());
  std::atomic<int> steps{0};
  std::atomic<bool> stop{false};
  std::thread stage([&] {
    while (!stop) {
      const MapStore::WriteAccess map = store.Write();
      std::this_thread::sleep_for(std::chrono::milliseconds(2));  // the step's work
      ++steps;
    }
  });
  while (steps < 3) std::this_thread::yield();
  for (int frame = 0; frame < 20; ++frame) {
    const int before = steps;
    const MapStore::WriteAccess map = store.WriteFirst();
    EXPECT_LE(steps - before, 2) << "frame " << frame;
    map->AddLandmark(Eigen::Vector3d(0, 0, 1), kNoKeyFrame);
  }
  stop = true;
  stage.join();
  EXPECT_EQ(store.Read()->NumLandmarks(), 20u);
}

}  // namespace
}  // namespace detslam
