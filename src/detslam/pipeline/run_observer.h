// A watcher of a run (e.g. the live viewer, viewer/live_viewer.h): the runner tells it about every
// frame from the tracking thread, and in sequential mode asks it before each frame, so that it can
// hold the run (pause, step).
#pragma once

#include <cstddef>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "detslam/map/frame.h"
#include "detslam/pipeline/slam_system.h"
#include "detslam/segmentation/segmenter.h"

namespace detslam {

struct RunSummary;

// One frame as the runner has just finished it. The pointers live for the call only.
struct ObservedFrame {
  const FrameReport* report = nullptr;
  const cv::Mat* bgr = nullptr;  // the colour image (null for a skipped frame)
  // The Det-SLAM stage's instances of the frame (null when the frame was not segmented).
  const std::vector<Instance>* instances = nullptr;
  const Frame* frame = nullptr;  // the frame as tracked (null for a skipped frame)
};

class RunObserver {
 public:
  virtual ~RunObserver() = default;
  // Before the first frame: frames in the run, and whether WaitBeforeFrame is called (sequential
  // mode).
  virtual void OnStart(size_t total_frames, bool pausable) = 0;
  // Sequential mode, before frame `index` is loaded: may block (a paused viewer) and read `slam`
  // meanwhile. Must return soon after the run's stop flag is set.
  virtual void WaitBeforeFrame(int64_t index, const SlamSystem& slam) = 0;
  // In the tracking thread after each frame (skipped ones too). Must not block: it delays the
  // next frame. `slam` may be read (its map store's lock is free).
  virtual void OnFrame(const ObservedFrame& frame, const SlamSystem& slam) = 0;
  // After the run's outputs are written (also after an interruption), before `slam` goes.
  virtual void OnFinish(const RunSummary& summary, const SlamSystem& slam) = 0;
};

}  // namespace detslam
