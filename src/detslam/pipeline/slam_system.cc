#include "detslam/pipeline/slam_system.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <sstream>

#include <spdlog/spdlog.h>

#include "detslam/core/atomic_file.h"
#include "detslam/core/check.h"
#include "detslam/map/map_file.h"
#include "detslam/mapping/map_bundle.h"
#include "detslam/place/default_vocabulary.h"

namespace detslam {
namespace {

double MsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// CPU time the calling thread has used, ms (-1 where the platform cannot tell).
double ThreadCpuMs() {
#if defined(CLOCK_THREAD_CPUTIME_ID)
  timespec ts{};
  if (clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts) == 0)
    return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
#endif
  return -1;
}

// Localisation mode tracks against the loaded map only: no new maps either.
TrackerOptions TrackerFor(const SlamOptions& options) {
  TrackerOptions t = options.tracker;
  if (options.localization) t.new_map_when_lost = false;
  return t;
}

}  // namespace

bool SlamOptions::Check(std::string* error) const {
  std::string e1, e2, e3, e4, e5;
  // Every check runs (each adds its own message), so the error names all the bad options at once.
  const bool passed[] = {orb.Check(&e1), tracker.Check(&e2), mapper.Check(&e3), dynamic.Check(&e4),
                         loop.Check(&e5)};
  bool ok = true;
  for (const bool p : passed) ok = ok && p;
  if (error) *error = e1 + e2 + e3 + e4 + e5;
  return ok;
}

ScaleInfo MakeScaleInfo(const OrbExtractor& extractor) {
  ScaleInfo s;
  s.scale_factors = extractor.scale_factors();
  s.level_sigma2 = extractor.level_sigma2();
  s.inv_level_sigma2 = extractor.inv_level_sigma2();
  s.log_scale_factor = std::log(extractor.options().scale_factor);
  return s;
}

SlamSystem::SlamSystem(const PinholeCamera& camera, const SlamOptions& options,
                       Segmenter* segmenter)
    : camera_(camera),
      options_(options),
      extractor_(options.orb),
      vocabulary_path_(options.vocabulary.empty() ? DefaultVocabularyPath() : options.vocabulary),
      vocabulary_(vocabulary_path_ == "none" ? nullptr : LoadSharedVocabulary(vocabulary_path_)),
      dynamic_(options.dynamic, segmenter),
      store_(MakeScaleInfo(extractor_)),
      tracker_(camera, TrackerFor(options), options.dynamic.geometric),
      mapper_(camera, options.mapper),
      loop_closer_(camera, options.loop) {
  std::string error;
  DETSLAM_CHECK_MSG(camera_.Check(&error), error);
}

SlamSystem::~SlamSystem() {
  stop_global_ba_ = true;
  WaitForGlobalBundleAdjustment();
}

void SlamSystem::WaitForGlobalBundleAdjustment() {
  if (global_ba_.joinable()) global_ba_.join();
}

void SlamSystem::Interrupt() {
  interrupted_ = true;  // before the stop flag: see where a global BA thread starts
  stop_global_ba_ = true;
}

std::vector<LoopRecord> SlamSystem::loops() const {
  const MapStore::ReadAccess map = store_.Read();
  return loops_;
}

void SlamSystem::MapKeyFrame(KeyFrameId kf, FrameReport* report) {
  const auto t0 = std::chrono::steady_clock::now();
  {
    // With loop closing in its own thread, a correction waits for this keyframe's local mapping.
    std::unique_lock<std::mutex> turn(mapping_turn_, std::defer_lock);
    if (options_.loop_thread) turn.lock();
    abort_local_ba_ = false;  // a request from before this keyframe was for the previous one
    LocalMappingControl control;
    control.keyframes_waiting = [this] { return keyframes_to_map_ > 1; };
    control.abort_ba = &abort_local_ba_;
    const LocalMappingSummary s = mapper_.ProcessKeyFrame(kf, &store_, control);
    if (s.skipped_for_waiting) ++keyframes_mapped_in_burst_;
    const MapStore::WriteAccess map = store_.Write();
    for (const ErasedKeyFrame& e : s.erased_keyframes) {
      erased_[e.id] = e;
      tracker_.OnKeyFrameErased(*map, e.id);
    }
  }
  if (!options_.loop_thread) CloseLoops(kf, report);
  report->timings.mapping_ms = MsSince(t0);
  {
    const MapStore::WriteAccess map = store_.Write();
    mapping_times_ms_.push_back(report->timings.mapping_ms);
  }
  --keyframes_to_map_;
}

void SlamSystem::CloseLoops(KeyFrameId kf, FrameReport* report) {
  const auto t0 = std::chrono::steady_clock::now();
  bool global_ba = false;
  // Loop closing in steps, each under its own write access, so that tracking goes on between
  // the candidate search and each candidate's verification; the correction and everything that
  // must move with it (the tracker, the bookkeeping) share the last step.
  double longest_step_ms = 0;  // the longest time tracking could have waited for loop closing
  const auto run_step = [&](const LoopCloser::MapStep& step) {
    const MapStore::WriteAccess map = store_.Write();
    const auto step_t0 = std::chrono::steady_clock::now();
    step(*map);
    longest_step_ms = std::max(longest_step_ms, MsSince(step_t0));
  };
  const auto finish = [&](Map& map, const LoopClosingResult& loop) {
    if (loop_closer_.has_pending()) tracker_.RequestKeyFrame();
    if (!loop.closed) return;
    tracker_.OnLoopClosed(map, loop.old_poses);
    report->loop_closed = true;
    report->loop_keyframe = loop.keyframe;
    report->loop_candidate = loop.candidate;
    report->loop_candidate_frame = map.keyframe(loop.candidate).frame_index;
    report->loop_inliers = loop.inliers;
    report->loop_agreeing = loop.agreeing;
    report->loop_correction_m = loop.correction_m;
    report->maps_merged = loop.merged;
    LoopRecord record;
    record.frame = map.keyframe(loop.keyframe).frame_index;
    record.keyframe = loop.keyframe;
    record.candidate = loop.candidate;
    record.candidate_frame = report->loop_candidate_frame;
    record.inliers = loop.inliers;
    record.agreeing = loop.agreeing;
    record.correction_m = loop.correction_m;
    record.candidate_from_keyframe = loop.candidate_from_keyframe;
    record.merge = loop.merged;
    record.merged_from = loop.merged_from;
    record.merged_into = loop.merged_into;
    record.welded_keyframes = loop.welded_keyframes;
    record.corrected_after_frame = last_tracked_frame_;
    loops_.push_back(record);
    ++loop_generation_;
    global_ba = options_.loop.global_ba_iterations > 0 && !interrupted_;
  };
  // A welded merge moves the map in two steps (the seam's bundle adjustment solved between them):
  // the tracker moves with the first one, and a global BA started before it is stale.
  const auto moved = [&](Map& map, const std::map<KeyFrameId, Rigid3d>& old_poses) {
    tracker_.OnLoopClosed(map, old_poses);
    ++loop_generation_;
  };
  // With its own thread, a correction holds local mapping (mapping_turn_) from just before the
  // closing step until its last step is done.
  std::unique_lock<std::mutex> turn(mapping_turn_, std::defer_lock);
  std::chrono::steady_clock::time_point held_since;
  double wait_ms = 0;
  const auto hold_mapping = [&] {
    if (!options_.loop_thread) return;
    const auto w0 = std::chrono::steady_clock::now();
    turn.lock();
    wait_ms = MsSince(w0);
    held_since = std::chrono::steady_clock::now();
  };
  loop_closer_.Process(run_step, kf, finish, moved, hold_mapping);
  const double held_ms = turn.owns_lock() ? MsSince(held_since) : 0.0;
  if (turn.owns_lock()) turn.unlock();
  {
    const MapStore::WriteAccess map = store_.Write();
    if (report->loop_closed) {
      loops_.back().map_locked_ms = longest_step_ms;
      loops_.back().mapping_wait_ms = wait_ms;
      loops_.back().mapping_held_ms = held_ms;
    }
    loop_closing_times_ms_.push_back(MsSince(t0));
  }
  if (global_ba) {
    // Without the lock: tracking (and, in its own thread, local mapping) goes on while the whole
    // map is solved; the result is applied under the lock, where the tracker is updated too.
    // A solution started before a newer loop's correction would undo it: the running one is
    // stopped after its current iteration and its solution discarded (ORB-SLAM3 stops its global
    // BA thread for a new loop too).
    auto run = [this, generation = loop_generation_] {
      GlobalBundleAdjustment(
          camera_, options_.loop.global_ba_iterations, &store_,
          [this](Map& map, const std::map<KeyFrameId, Rigid3d>& old_poses) {
            tracker_.OnLoopClosed(map, old_poses);
            global_ba_applied_.push_back(last_tracked_frame_);
          },
          [this, generation](const Map&) { return loop_generation_ == generation; },
          &stop_global_ba_);
      global_ba_running_ = false;
    };
    ++global_ba_runs_;
    if (options_.global_ba_thread) {
      if (global_ba_running_) {  // one at a time: a newer loop stops the running one
        stop_global_ba_ = true;
        ++global_ba_stopped_;
        spdlog::info("global bundle adjustment stopped: a newer loop was closed");
      }
      WaitForGlobalBundleAdjustment();
      stop_global_ba_ = false;
      global_ba_running_ = true;
      if (interrupted_) stop_global_ba_ = true;  // Interrupt() came after the check above
      global_ba_ = std::thread(run);
    } else {
      run();
    }
  }
}

std::vector<double> SlamSystem::mapping_times_ms() const {
  const MapStore::ReadAccess map = store_.Read();
  return mapping_times_ms_;
}

std::vector<double> SlamSystem::loop_closing_times_ms() const {
  const MapStore::ReadAccess map = store_.Read();
  return loop_closing_times_ms_;
}

MapFileInfo SlamSystem::LoadMap(const std::string& path) {
  MapFileExpectation expected;
  expected.camera = camera_;
  expected.scale = MakeScaleInfo(extractor_);
  expected.vocabulary_checksum = vocabulary_ ? vocabulary_->Checksum() : 0;
  MapFileInfo info;
  Map loaded = LoadMapFile(path, expected, &info);
  if (loaded.NumKeyFrames() == 0) throw InputError(path, 0, "map file: the map has no keyframes");
  const MapStore::WriteAccess map = store_.Write();
  DETSLAM_CHECK_MSG(map->NumKeyFrames() == 0 && tracked_.empty(),
                    "LoadMap must come before the first frame");
  *map = std::move(loaded);
  tracker_.StartInLoadedMap();
  spdlog::info("{}: loaded {} keyframes and {} map points; relocalising", path,
               map->NumKeyFrames(), map->NumLandmarks());
  return info;
}

uint64_t SlamSystem::SaveMap(const std::string& path) const {
  std::string bytes;
  {
    const MapStore::ReadAccess map = store_.Read();
    bytes = EncodeMapFile(*map, camera_, vocabulary_ ? vocabulary_->Checksum() : 0);
  }
  WriteBytesAtomically(path, bytes);
  return bytes.size();
}

int SlamSystem::global_ba_runs() const { return global_ba_runs_; }

int SlamSystem::global_ba_stopped() const { return global_ba_stopped_; }

std::vector<int64_t> SlamSystem::global_ba_applied_after_frames() const {
  const MapStore::ReadAccess map = store_.Read();
  return global_ba_applied_;
}

int SlamSystem::loops_closed() const {
  const MapStore::ReadAccess map = store_.Read();
  return loop_closer_.loops_closed();
}

int SlamSystem::maps_merged() const {
  const MapStore::ReadAccess map = store_.Read();
  return loop_closer_.maps_merged();
}

LoopDetectionStats SlamSystem::loop_detection_stats() const {
  const MapStore::ReadAccess map = store_.Read();
  return loop_closer_.stats();
}

FrameReport SlamSystem::ProcessFrame(int64_t index, Timestamp stamp, const cv::Mat& gray,
                                     const cv::Mat& depth_m, const cv::Mat& ignore_mask) {
  FrameReport report;
  Frame frame = ExtractFrame(index, stamp, gray, depth_m, ignore_mask, &report);
  const KeyFrameId kf = TrackFrame(std::move(frame), &report);
  if (kf != kNoKeyFrame) MapKeyFrame(kf, &report);
  return report;
}

FrameInstances SlamSystem::SegmentFrame(const SegmenterInput& input, const cv::Mat& gray) {
  return dynamic_.Segment(input, gray);
}

FrameInstances SlamSystem::DetectFrame(const SegmenterInput& input) {
  return dynamic_.Detect(input);
}

Frame SlamSystem::ExtractFrame(int64_t index, Timestamp stamp, const cv::Mat& gray,
                               const cv::Mat& depth_m, const cv::Mat& ignore_mask,
                               FrameReport* report, const std::vector<Instance>* instances,
                               const OrbPyramid* pyramid) const {
  const auto t0 = std::chrono::steady_clock::now();
  LabelledKeypoints all =
      dynamic_.Extract(extractor_, gray, depth_m, ignore_mask, instances, pyramid);
  report->dynamic_instances = all.instances_used;
  // Static keypoints go to tracking; the others stay in the frame for diagnostics only.
  std::vector<cv::KeyPoint> kept, rejected;
  std::vector<float> kept_depth;
  std::vector<KeypointLabel> rejected_labels;
  cv::Mat kept_desc;
  if (std::all_of(all.labels.begin(), all.labels.end(),
                  [](KeypointLabel l) { return l == KeypointLabel::kStatic; })) {
    kept = std::move(all.keypoints);
    kept_depth = std::move(all.depth);
    kept_desc = all.descriptors;
  } else {
    for (size_t i = 0; i < all.keypoints.size(); ++i) {
      if (all.labels[i] == KeypointLabel::kStatic) {
        kept.push_back(all.keypoints[i]);
        kept_depth.push_back(all.depth[i]);
        kept_desc.push_back(all.descriptors.row(static_cast<int>(i)));
      } else {
        rejected.push_back(all.keypoints[i]);
        rejected_labels.push_back(all.labels[i]);
      }
    }
  }
  report->rejected_keypoints = static_cast<int>(rejected.size());
  Frame frame;
  frame.index = index;
  frame.stamp = stamp;
  frame.withheld = std::move(all.withheld);
  auto features = BuildFrameFeatures(camera_, std::move(kept), kept_desc, std::move(kept_depth));
  features->rejected_keypoints = std::move(rejected);
  features->rejected_labels = std::move(rejected_labels);
  if (vocabulary_) ComputeFrameBow(*vocabulary_, features.get());
  frame.features = std::move(features);
  report->index = index;
  report->stamp = stamp;
  report->num_keypoints = static_cast<int>(frame.size());
  report->timings.extraction_ms = MsSince(t0);
  return frame;
}

KeyFrameId SlamSystem::TrackFrame(Frame frame, FrameReport* report, Frame* tracked) {
  auto t0 = std::chrono::steady_clock::now();
  const double cpu0 = ThreadCpuMs();
  const MapStore::WriteAccess access = store_.WriteFirst();
  report->timings.map_wait_ms = MsSince(t0);
  Map& map = *access;
  const size_t kfs_before = map.NumKeyFrames();
  last_tracked_frame_ = report->index;
  LocalMappingState mapping;  // idle in sequential runs: each keyframe is mapped before the next frame
  const int to_map = keyframes_to_map_;
  mapping.idle = to_map == 0;
  mapping.queued = std::max(0, to_map - 1);
  const DetSlamOptions& dyn = options_.dynamic;
  // Before tracking, so that the frame does not match the points this drops.
  if (report->mask_age >= 0 && dyn.keyframe_clean_own_masks)
    report->keyframe_cleaned = CleanKeyFrameWithOwnMasks(map);
  report->tracking = tracker_.Track(map, &frame, mapping);
  if (report->tracking.interrupt_local_ba) abort_local_ba_ = true;
  KeyFrameId new_kf = kNoKeyFrame;
  // Asynchronous segmentation: masks carried over more than keyframe_max_mask_age frames.
  const bool stale = report->mask_age > dyn.keyframe_max_mask_age;
  if (report->tracking.pose_valid && report->tracking.need_keyframe && !options_.localization) {
    // No new map points from stale masks, unless tracking is getting weak or the keyframe has
    // waited keyframe_max_wait frames.
    if (stale && keyframe_wait_since_ < 0) keyframe_wait_since_ = report->index;
    if (stale && report->tracking.num_inliers >= dyn.keyframe_defer_min_inliers &&
        report->index - keyframe_wait_since_ < dyn.keyframe_max_wait) {
      report->keyframe_deferred = true;
    } else {
      new_kf = tracker_.CreateKeyFrame(map, &frame);
      keyframe_wait_since_ = -1;
    }
  }
  if (map.NumKeyFrames() > kfs_before && new_kf == kNoKeyFrame) {
    new_kf = tracker_.reference_keyframe();  // a new map's first keyframe, whatever its masks' age
    keyframe_wait_since_ = -1;
  }
  if (new_kf != kNoKeyFrame) {
    ++keyframes_to_map_;
    report->keyframe_stale_masks = stale;
  }
  report->timings.tracking_ms = MsSince(t0);
  const double cpu1 = ThreadCpuMs();
  report->timings.tracking_cpu_ms = cpu0 >= 0 && cpu1 >= 0 ? cpu1 - cpu0 : -1;

  if (report->tracking.pose_valid) {
    const KeyFrameId ref = frame.reference_keyframe != kNoKeyFrame ? frame.reference_keyframe
                                                                   : tracker_.reference_keyframe();
    tracked_.push_back(
        {frame.stamp, ref, *frame.cam_from_world * map.keyframe(ref).cam_from_world.Inverse()});
    report->map_id = map.MapOf(ref);
    report->world_from_cam = frame.cam_from_world->Inverse();
  }
  report->keyframe = new_kf != kNoKeyFrame;
  report->map_keyframes = static_cast<int>(map.NumKeyFrames());
  report->map_points = static_cast<int>(map.NumLandmarks());
  if (tracked != nullptr) *tracked = std::move(frame);
  return new_kf;
}

void SlamSystem::OfferOwnMasks(int64_t index, const std::vector<Instance>& instances,
                               const cv::Mat& depth_m) {
  if (!options_.dynamic.keyframe_clean_own_masks) return;
  OwnMasks masks{index, dynamic_.Regions(instances, depth_m, cv::Size(camera_.width, camera_.height))};
  const std::lock_guard<std::mutex> lock(offered_mutex_);
  if (!offered_ || offered_->index < index) offered_ = std::move(masks);
}

int SlamSystem::CleanKeyFrameWithOwnMasks(Map& map) {
  std::optional<OwnMasks> masks;
  {
    const std::lock_guard<std::mutex> lock(offered_mutex_);
    masks.swap(offered_);
  }
  if (!masks) return -1;
  // The keyframe made from that frame, if any (among the newest: masks come within a second).
  KeyFrameId id = kNoKeyFrame;
  int looked = 0;
  for (auto it = map.keyframes().rbegin(); it != map.keyframes().rend() && looked < 30; ++it, ++looked) {
    if (it->second.frame_index == masks->index) {
      id = it->first;  // one keyframe per frame at most
      break;
    }
  }
  if (id == kNoKeyFrame) return -1;
  KeyFrame& kf = map.keyframe(id);
  const FrameFeatures& f = *kf.features;
  std::vector<KeypointLabel> labels(f.size(), KeypointLabel::kStatic);
  masks->regions.Label(f.keypoints, f.depth, &labels);
  if (kf.labels.size() != f.size()) kf.labels.assign(f.size(), KeypointLabel::kStatic);
  int relabelled = 0;
  for (size_t i = 0; i < f.size(); ++i) {
    if (labels[i] == KeypointLabel::kStatic || kf.labels[i] != KeypointLabel::kStatic) continue;
    kf.labels[i] = labels[i];
    ++relabelled;
    const LandmarkId lm = kf.landmarks[i];
    if (lm == kNoLandmark || !map.HasLandmark(lm)) continue;
    // A point this keyframe made lies on the object: gone; an older point only loses this view.
    if (map.landmark(lm).first_keyframe == id) {
      map.EraseLandmark(lm);
    } else {
      map.EraseObservation(lm, id);
    }
  }
  if (relabelled > 0) map.UpdateConnections(id);
  return relabelled;
}

Rigid3d SlamSystem::ReferenceWorldFromCam(const Map& map, KeyFrameId id,
                                          const Rigid3d& cam_from_ref,
                                          KeyFrameId* existing) const {
  // Walk up through erased keyframes to one that still exists.
  Rigid3d cam_from_kf = cam_from_ref;
  KeyFrameId kf = id;
  for (int guard = 0; !map.HasKeyFrame(kf) && guard < 100000; ++guard) {
    auto it = erased_.find(kf);
    DETSLAM_CHECK_MSG(it != erased_.end(), "keyframe " << kf << " vanished without a record");
    cam_from_kf = cam_from_kf * it->second.cam_from_parent;
    kf = it->second.parent;
  }
  if (existing) *existing = kf;
  return (cam_from_kf * map.keyframe(kf).cam_from_world).Inverse();
}

MapTrajectories SlamSystem::FrameTrajectories() const {
  const MapStore::ReadAccess map = store_.Read();
  MapTrajectories out;
  for (const TrackedFrame& t : tracked_) {
    KeyFrameId kf = kNoKeyFrame;
    const Rigid3d world_from_cam = ReferenceWorldFromCam(*map, t.reference, t.cam_from_ref, &kf);
    const int map_id = map->MapOf(kf);
    if (out.main_map < 0) out.main_map = map_id;
    out.by_map[map_id].push_back({t.stamp, world_from_cam});
  }
  return out;
}

Trajectory SlamSystem::FrameTrajectory() const {
  MapTrajectories all = FrameTrajectories();
  return all.main_map < 0 ? Trajectory() : std::move(all.by_map[all.main_map]);
}

Trajectory SlamSystem::KeyFrameTrajectory() const {
  const MapStore::ReadAccess map = store_.Read();
  Trajectory out;
  if (tracked_.empty()) return out;
  KeyFrameId first = kNoKeyFrame;
  ReferenceWorldFromCam(*map, tracked_.front().reference, tracked_.front().cam_from_ref, &first);
  const int main_map = map->MapOf(first);
  for (const auto& [id, kf] : map->keyframes()) {
    if (kf.map_id == main_map) out.push_back({kf.stamp, kf.cam_from_world.Inverse()});
  }
  return out;
}

}  // namespace detslam
