#include "detslam/viewer/live_viewer.h"

#include <algorithm>
#include <unordered_set>

#include "detslam/pipeline/runner.h"
#include "detslam/tracking/tracker.h"

namespace detslam {
namespace {

int64_t SteadyNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

void AddKeypoint(ViewerFrame* f, KeypointFate fate, const cv::KeyPoint& kp) {
  std::vector<float>& v = f->keypoints[static_cast<int>(fate)];
  v.push_back(kp.pt.x);
  v.push_back(kp.pt.y);
}

KeypointFate FateOfRejected(KeypointLabel label) {
  switch (label) {
    case KeypointLabel::kDynamicDepth: return KeypointFate::kDepth;
    case KeypointLabel::kGeometric: return KeypointFate::kGeometric;
    default: return KeypointFate::kMask;
  }
}

// The frame panel's snapshot of a frame the runner has just finished.
std::shared_ptr<ViewerFrame> MakeViewerFrame(const ObservedFrame& in) {
  auto f = std::make_shared<ViewerFrame>();
  const FrameReport& r = *in.report;
  f->index = r.index;
  f->stamp_s = r.stamp.Seconds();
  f->skipped = r.skipped;
  f->state = ToString(r.tracking.state);
  f->method = r.tracking.method;
  f->tracked = r.tracking.pose_valid;
  f->keyframe = r.keyframe;
  f->inliers = r.tracking.num_inliers;
  f->dynamic_instances = r.dynamic_instances;
  f->frame_ms = r.segmentation_ms + r.timings.extraction_ms + r.timings.tracking_ms +
                r.timings.mapping_ms;
  f->map_id = r.map_id;
  if (r.tracking.pose_valid) f->world_from_cam = r.world_from_cam;
  if (in.bgr != nullptr) f->bgr = *in.bgr;  // shares the pixels: the runner never writes them again
  if (in.instances != nullptr) {
    for (const Instance& inst : *in.instances) {
      if (!inst.mask.empty()) f->masks.push_back(inst.mask);
      f->boxes.push_back(inst.box);
    }
  }
  const detslam::Frame* frame = in.frame;
  if (frame != nullptr && frame->features) {
    f->has_keypoints = true;
    const FrameFeatures& feat = *frame->features;
    for (size_t i = 0; i < feat.size(); ++i) {
      KeypointFate fate = KeypointFate::kUnmatched;
      if (i < frame->labels.size() && frame->labels[i] == KeypointLabel::kGeometric) {
        fate = KeypointFate::kGeometric;
      } else if (i < frame->landmarks.size() && frame->landmarks[i] != kNoLandmark &&
                 !(i < frame->outlier.size() && frame->outlier[i])) {
        fate = KeypointFate::kMatched;
      }
      AddKeypoint(f.get(), fate, feat.keypoints[i]);
    }
    for (size_t i = 0; i < feat.rejected_keypoints.size(); ++i) {
      const KeypointLabel label =
          i < feat.rejected_labels.size() ? feat.rejected_labels[i] : KeypointLabel::kDynamicMask;
      AddKeypoint(f.get(), FateOfRejected(label), feat.rejected_keypoints[i]);
    }
  }
  return f;
}

}  // namespace

LiveViewer::LiveViewer(LiveViewerOptions options) : options_(std::move(options)) {
  options_.ground_truth = SortedUnique(std::move(options_.ground_truth));
  counters_.mode = "live";
  counters_.paused = options_.start_paused;
  if (options_.frames_kept == 0) options_.frames_kept = 1;
}

void LiveViewer::OnStart(size_t total_frames, bool pausable) {
  std::lock_guard<std::mutex> lock(mutex_);
  counters_.total = static_cast<int64_t>(total_frames);
  counters_.pausable = pausable;
  if (!pausable) counters_.paused = false;
  Publish();
}

bool LiveViewer::Watched() const {
  if (clients_.load() > 0) return true;
  // A page (or a test) polling without the update stream counts for 3 s after its request.
  const int64_t last = last_request_ns_.load();
  return last != 0 && SteadyNs() - last < 3'000'000'000LL;
}

void LiveViewer::WaitBeforeFrame(int64_t /*index*/, const SlamSystem& slam) {
  std::unique_lock<std::mutex> lock(mutex_);
  while (counters_.paused && steps_ == 0) {
    if (options_.stop != nullptr && options_.stop->load()) return;
    if (map_wanted_) {
      map_wanted_ = false;
      lock.unlock();
      TakeMapSnapshot(slam, current_map_);
      lock.lock();
      continue;
    }
    // The stop flag is set from a signal handler, which cannot notify: look every 50 ms.
    changed_.wait_for(lock, std::chrono::milliseconds(50));
  }
  if (steps_ > 0) --steps_;
}

void LiveViewer::OnFrame(const ObservedFrame& observed, const SlamSystem& slam) {
  const auto start = std::chrono::steady_clock::now();
  std::shared_ptr<ViewerFrame> frame = MakeViewerFrame(observed);
  const FrameReport& r = *observed.report;
  const auto now = std::chrono::steady_clock::now();
  bool map_due = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ViewerCounters& c = counters_;
    c.frame = r.index;
    c.state = r.skipped.empty() ? ToString(r.tracking.state) : "skipped";
    ++c.frames_done;
    if (r.tracking.pose_valid) ++c.tracked;
    if (r.tracking.relocalized) ++c.relocalizations;
    if (r.tracking.method == "init" || r.tracking.new_map) ++c.maps;
    if (r.loop_closed) ++(r.maps_merged ? c.merges : c.loops);
    if (r.skipped.empty()) {
      c.keyframes = r.map_keyframes;
      c.points = r.map_points;
    }
    frame_times_.push_back(now);
    while (frame_times_.size() > 30) frame_times_.pop_front();
    if (frame_times_.size() >= 2) {
      const double s =
          std::chrono::duration<double>(frame_times_.back() - frame_times_.front()).count();
      c.fps = s > 0 ? (frame_times_.size() - 1) / s : 0.0;
    }
    if (r.map_id >= 0) current_map_ = r.map_id;
    frame->seq = update_ + 1;
    frames_.push_back(std::move(frame));
    while (frames_.size() > options_.frames_kept) frames_.pop_front();
    map_due = now - last_map_time_ >= options_.map_period;
    Publish();
  }
  if (map_due && Watched()) TakeMapSnapshot(slam, current_map_);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::lock_guard<std::mutex> lock(mutex_);
  on_frame_ms_sum_ += ms;  // map snapshots included
  on_frame_ms_max_ = std::max(on_frame_ms_max_, ms);
}

LiveViewer::Cost LiveViewer::cost() const {
  std::lock_guard<std::mutex> lock(mutex_);
  Cost c;
  c.frames = static_cast<uint64_t>(counters_.frames_done);
  c.on_frame_ms_mean = c.frames ? on_frame_ms_sum_ / c.frames : 0.0;
  c.on_frame_ms_max = on_frame_ms_max_;
  c.map_snapshots = map_snapshots_.load();
  c.map_snapshot_ms_mean = c.map_snapshots ? snapshot_ms_sum_ / c.map_snapshots : 0.0;
  c.map_snapshot_ms_max = snapshot_ms_max_;
  return c;
}

void LiveViewer::OnFinish(const RunSummary& summary, const SlamSystem& slam) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    counters_.finished = true;
    counters_.paused = false;
    counters_.loops = static_cast<int64_t>(summary.loops);
    counters_.merges = summary.maps_merged;
    counters_.keyframes = static_cast<int64_t>(summary.keyframes);
    counters_.points = static_cast<int64_t>(summary.landmarks);
    Publish();
  }
  // The final poses (after the last loop correction and global BA), whether watched or not, for
  // a page that connects after the run (--viewer-keep).
  TakeMapSnapshot(slam, current_map_);
}

void LiveViewer::TakeMapSnapshot(const SlamSystem& slam, int map_id) {
  const auto start = std::chrono::steady_clock::now();
  auto m = std::make_shared<ViewerMap>();
  const MapTrajectories trajectories = slam.FrameTrajectories();
  if (map_id < 0) map_id = trajectories.main_map;
  m->map_id = map_id;
  {
    const MapStore::ReadAccess access = slam.ReadMap();
    const detslam::Map& map = *access;
    std::unordered_set<KeyFrameId> in_map;
    for (const auto& [id, kf] : map.keyframes()) {
      if (kf.map_id != map_id) continue;
      in_map.insert(id);
      m->keyframes.push_back(kf.cam_from_world.Inverse());
    }
    m->points.reserve(3 * map.NumLandmarks());
    for (const auto& [id, lm] : map.landmarks()) {
      if (in_map.count(lm.reference_keyframe) == 0) continue;
      for (int k = 0; k < 3; ++k) m->points.push_back(static_cast<float>(lm.position[k]));
    }
  }
  const auto it = trajectories.by_map.find(map_id);
  if (it != trajectories.by_map.end()) {
    for (const StampedPose& p : it->second) m->trajectory.push_back(p.world_from_cam.translation());
    m->ground_truth = GroundTruthInEstimateFrame(options_.ground_truth, SortedUnique(it->second));
  }
  std::lock_guard<std::mutex> lock(mutex_);
  m->seq = update_ + 1;
  map_ = std::move(m);
  last_map_time_ = std::chrono::steady_clock::now();
  ++map_snapshots_;
  const double ms = std::chrono::duration<double, std::milli>(last_map_time_ - start).count();
  snapshot_ms_sum_ += ms;
  snapshot_ms_max_ = std::max(snapshot_ms_max_, ms);
  Publish();
}

void LiveViewer::Publish() {
  ++update_;
  changed_.notify_all();
}

uint64_t LiveViewer::WaitForUpdate(uint64_t seen, std::chrono::milliseconds timeout) {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait_for(lock, timeout, [&] { return update_ > seen; });
  return update_;
}

ViewerCounters LiveViewer::Counters() const {
  last_request_ns_ = SteadyNs();
  std::lock_guard<std::mutex> lock(mutex_);
  ViewerCounters c = counters_;
  c.pages = clients_.load();
  c.seq = update_;
  return c;
}

std::shared_ptr<const ViewerFrame> LiveViewer::Frame(int64_t index) {
  last_request_ns_ = SteadyNs();
  std::lock_guard<std::mutex> lock(mutex_);
  if (frames_.empty()) return nullptr;
  if (index < 0) return frames_.back();
  for (const auto& f : frames_) {
    if (f->index == index) return f;
  }
  return nullptr;
}

std::shared_ptr<const ViewerMap> LiveViewer::Map() {
  last_request_ns_ = SteadyNs();
  std::lock_guard<std::mutex> lock(mutex_);
  // While paused the runner waits in WaitBeforeFrame and takes a snapshot there.
  if (counters_.paused && !counters_.finished &&
      (map_ == nullptr || map_->seq < (frames_.empty() ? 0 : frames_.back()->seq))) {
    map_wanted_ = true;
    changed_.notify_all();
  }
  return map_;
}

bool LiveViewer::Control(const std::string& action, std::string* error) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (action != "pause" && action != "resume" && action != "step") {
    *error = "unknown action '" + action + "' (pause, resume or step)";
    return false;
  }
  if (!counters_.pausable) {
    *error = "pause and step need a sequential run (this one is threaded)";
    return false;
  }
  if (counters_.finished) {
    *error = "the run has finished";
    return false;
  }
  if (action == "pause") {
    counters_.paused = true;
  } else if (action == "resume") {
    counters_.paused = false;
    steps_ = 0;
  } else {
    counters_.paused = true;
    ++steps_;
  }
  Publish();
  return true;
}

void LiveViewer::ClientsChanged(int delta) { clients_ += delta; }

}  // namespace detslam
