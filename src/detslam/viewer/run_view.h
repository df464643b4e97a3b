// The viewer's content for a finished run (`detslam view RUN_DIR`): the run folder's map.ply,
// keyframes.txt, trajectory.txt and run.json (counters and the per-frame log), the frames'
// images from the dataset the run read (when it can still be opened) with the keyframes' removed
// pixels (keyframe_masks/) drawn over them, and the ground truth aligned like the TUM tools do.
#pragma once

#include <memory>
#include <mutex>
#include <string>

#include "detslam/core/camera.h"
#include "detslam/eval/run_log.h"
#include "detslam/io/rgbd_source.h"
#include "detslam/io/trajectory.h"
#include "detslam/viewer/viewer_content.h"

namespace detslam {

struct RunViewInputs {
  std::string run_dir;
  // The run's frames (may be null: the page then shows no images) and their camera.
  std::unique_ptr<RgbdSource> source;
  PinholeCamera camera;
  Trajectory ground_truth;  // may be empty
};

class RunView : public ViewerContent {
 public:
  // Throws InputError naming the file when run.json or trajectory.txt cannot be read; a missing
  // map.ply or keyframes.txt leaves that part empty (with a warning).
  explicit RunView(RunViewInputs inputs);

  std::string Title() const override { return title_; }
  uint64_t WaitForUpdate(uint64_t seen, std::chrono::milliseconds timeout) override;
  ViewerCounters Counters() const override { return counters_; }
  std::shared_ptr<const ViewerFrame> Frame(int64_t index) override;
  std::shared_ptr<const ViewerMap> Map() override { return map_; }
  bool Control(const std::string& action, std::string* error) override;
  void ClientsChanged(int) override {}

 private:
  RunViewInputs in_;
  RunLog log_;
  Trajectory trajectory_;
  std::string title_;
  ViewerCounters counters_;
  std::shared_ptr<const ViewerMap> map_;
  std::mutex mutex_;  // guards the source (one Load at a time) and the cache
  std::shared_ptr<const ViewerFrame> cached_;
};

}  // namespace detslam
