#include "detslam/viewer/run_view.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <thread>

#include "detslam/core/check.h"
#include "detslam/io/ply.h"

namespace detslam {
namespace fs = std::filesystem;

RunView::RunView(RunViewInputs inputs) : in_(std::move(inputs)) {
  const fs::path dir(in_.run_dir);
  log_ = ReadRunLog((dir / "run.json").string());
  trajectory_ = SortedUnique(ReadTumTrajectory((dir / "trajectory.txt").string()));
  title_ = "finished run " + in_.run_dir + " on " + log_.dataset + " (segmenter " +
           (log_.segmenter.empty() ? "none" : log_.segmenter) + ", " + log_.mode + ")";
  ViewerCounters& c = counters_;
  c.mode = "run";
  if (!log_.per_frame.empty()) c.state = log_.per_frame.back().state;  // after the last frame
  c.frames_done = log_.frames;
  c.total = log_.per_frame.empty() ? log_.frames : static_cast<int64_t>(log_.per_frame.size());
  c.tracked = log_.frames_tracked;
  c.keyframes = log_.keyframes;
  c.points = log_.map_points;
  c.loops = log_.loops_closed;
  c.merges = log_.maps.merged;
  c.maps = std::max(1, log_.maps.started);
  c.relocalizations = log_.relocalizations;
  c.fps = log_.FramesPerSecond();
  c.finished = true;

  auto map = std::make_shared<ViewerMap>();
  map->seq = 1;
  map->map_id = log_.maps.main;
  const fs::path ply = dir / "map.ply";
  if (fs::exists(ply)) {
    const PointCloud cloud = ReadPointCloudPly(ply.string());
    map->points.reserve(3 * cloud.points.size());
    for (const Eigen::Vector3d& p : cloud.points)
      for (int k = 0; k < 3; ++k) map->points.push_back(static_cast<float>(p[k]));
  } else {
    spdlog::warn("{} not found: no map points", ply.string());
  }
  const fs::path keyframes = dir / "keyframes.txt";
  if (fs::exists(keyframes)) {
    for (const StampedPose& p : ReadTumTrajectory(keyframes.string()))
      map->keyframes.push_back(p.world_from_cam);
  } else {
    spdlog::warn("{} not found: no keyframes", keyframes.string());
  }
  for (const StampedPose& p : trajectory_) map->trajectory.push_back(p.world_from_cam.translation());
  map->ground_truth = GroundTruthInEstimateFrame(SortedUnique(in_.ground_truth), trajectory_);
  map_ = std::move(map);
}

uint64_t RunView::WaitForUpdate(uint64_t seen, std::chrono::milliseconds timeout) {
  // A finished run never changes: its one update is number 1.
  if (seen >= 1) std::this_thread::sleep_for(timeout);
  return 1;
}

bool RunView::Control(const std::string&, std::string* error) {
  *error = "a finished run cannot be paused or stepped";
  return false;
}

std::shared_ptr<const ViewerFrame> RunView::Frame(int64_t index) {
  if (index < 0) index = 0;
  std::lock_guard<std::mutex> lock(mutex_);
  if (cached_ && cached_->index == index) return cached_;
  const RunFrameLog* entry = nullptr;
  for (const RunFrameLog& l : log_.per_frame) {
    if (l.index == index) {
      entry = &l;
      break;
    }
  }
  if (entry == nullptr) return nullptr;
  auto f = std::make_shared<ViewerFrame>();
  f->seq = static_cast<uint64_t>(index) + 1;
  f->index = index;
  f->stamp_s = entry->stamp;
  f->state = entry->state;
  f->method = entry->method;
  f->tracked = entry->tracked;
  f->keyframe = entry->keyframe;
  f->inliers = entry->inliers;
  f->dynamic_instances = entry->dynamic_instances;
  f->frame_ms =
      entry->segmentation_ms + entry->extraction_ms + entry->tracking_ms + entry->mapping_ms;
  f->map_id = entry->final_map;
  // Its final pose (trajectory.txt), matched by the stamp to the microsecond.
  const Timestamp stamp = Timestamp::FromSeconds(entry->stamp);
  const auto it = std::lower_bound(
      trajectory_.begin(), trajectory_.end(), stamp,
      [](const StampedPose& p, Timestamp t) { return p.stamp < t; });
  const auto take_if_same = [&](Trajectory::const_iterator c) {
    if (c != trajectory_.end() && std::abs(c->stamp.Seconds() - entry->stamp) < 1e-6)
      f->world_from_cam = c->world_from_cam;
  };
  if (it != trajectory_.begin()) take_if_same(it - 1);
  take_if_same(it);
  if (in_.source && static_cast<size_t>(index) < in_.source->size()) {
    try {
      f->bgr = in_.source->Load(static_cast<size_t>(index), in_.camera).bgr;
    } catch (const InputError& e) {
      f->skipped = e.what();
    }
  }
  char name[32];
  std::snprintf(name, sizeof(name), "%06lld.png", static_cast<long long>(index));
  const fs::path mask_file = fs::path(in_.run_dir) / "keyframe_masks" / name;
  if (!f->bgr.empty() && fs::exists(mask_file)) {
    const cv::Mat mask = cv::imread(mask_file.string(), cv::IMREAD_GRAYSCALE);
    if (!mask.empty() && mask.size() == f->bgr.size()) f->masks.push_back(mask);
  }
  cached_ = f;
  return f;
}

}  // namespace detslam
