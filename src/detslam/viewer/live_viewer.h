// The viewer's content during a run: a RunObserver that keeps the newest frames and, while a page
// is connected, a map snapshot at most every `map_period` (taken in the tracking thread under the
// map's read lock), and that holds a sequential run while paused.
//
// Cost to the run: per frame, copies of the keypoint positions by fate and of the image's header
// (no pixels); map snapshots only while a page is connected. The tracking thread never waits for
// a page: a slow page misses frames (it is always given the newest).
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <string>

#include "detslam/io/trajectory.h"
#include "detslam/pipeline/run_observer.h"
#include "detslam/viewer/viewer_content.h"

namespace detslam {

struct LiveViewerOptions {
  std::string title;                                    // dataset and settings, for the page
  Trajectory ground_truth;                              // drawn aligned when not empty
  std::chrono::milliseconds map_period{500};            // at most one map snapshot per period
  size_t frames_kept = 8;                               // newest frame snapshots kept
  bool start_paused = false;                            // sequential: wait for step/resume
  const std::atomic<bool>* stop = nullptr;              // the run's stop flag (ends a pause)
};

class LiveViewer : public RunObserver, public ViewerContent {
 public:
  explicit LiveViewer(LiveViewerOptions options);

  // RunObserver
  void OnStart(size_t total_frames, bool pausable) override;
  void WaitBeforeFrame(int64_t index, const SlamSystem& slam) override;
  void OnFrame(const ObservedFrame& frame, const SlamSystem& slam) override;
  void OnFinish(const RunSummary& summary, const SlamSystem& slam) override;

  // ViewerContent
  std::string Title() const override { return options_.title; }
  uint64_t WaitForUpdate(uint64_t seen, std::chrono::milliseconds timeout) override;
  ViewerCounters Counters() const override;
  std::shared_ptr<const ViewerFrame> Frame(int64_t index) override;
  std::shared_ptr<const ViewerMap> Map() override;
  bool Control(const std::string& action, std::string* error) override;
  void ClientsChanged(int delta) override;

  // Map snapshots taken so far (0 while no page connected: the cost test).
  uint64_t map_snapshots() const { return map_snapshots_.load(); }
  // The viewer's own cost to the run: time in OnFrame (in the tracking thread) and in map
  // snapshots (taken in the tracking thread while a page is connected).
  struct Cost {
    uint64_t frames = 0;
    double on_frame_ms_mean = 0, on_frame_ms_max = 0;
    uint64_t map_snapshots = 0;
    double map_snapshot_ms_mean = 0, map_snapshot_ms_max = 0;
  };
  Cost cost() const;

 private:
  bool Watched() const;
  void TakeMapSnapshot(const SlamSystem& slam, int map_id);
  void Publish();  // update number + 1, wakes the waiting pages (mutex_ held)

  LiveViewerOptions options_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;  // new frame or map, pause state (pages and the runner wait)
  uint64_t update_ = 0;
  ViewerCounters counters_;
  std::deque<std::shared_ptr<const ViewerFrame>> frames_;  // newest last
  std::shared_ptr<const ViewerMap> map_;
  bool map_wanted_ = false;  // a page asked while the run was paused: the runner takes one
  int steps_ = 0;            // frames to run while paused
  int current_map_ = -1;
  std::deque<std::chrono::steady_clock::time_point> frame_times_;  // for the frame rate
  std::chrono::steady_clock::time_point last_map_time_{};
  std::atomic<int> clients_{0};
  mutable std::atomic<int64_t> last_request_ns_{0};  // steady clock of the last page request
  std::atomic<uint64_t> map_snapshots_{0};
  // Cost (under mutex_): sums and maxima in milliseconds.
  double on_frame_ms_sum_ = 0, on_frame_ms_max_ = 0, snapshot_ms_sum_ = 0, snapshot_ms_max_ = 0;
};

}  // namespace detslam
