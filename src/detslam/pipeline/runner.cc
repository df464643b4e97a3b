#include "detslam/pipeline/runner.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <functional>
#include <mutex>
#include <nlohmann/json.hpp>
#include <numeric>
#include <thread>

#include "detslam/core/atomic_file.h"
#include "detslam/core/check.h"
#include "detslam/dynamic/dynamic_filter.h"
#include "detslam/io/ply.h"
#include "detslam/pipeline/bounded_queue.h"
#include "detslam/pipeline/settings_keys.h"
#include "detslam/pipeline/stage_threads.h"

namespace detslam {
namespace {

nlohmann::json StatsJson(const ErrorStats& s) {
  return {{"count", s.count}, {"median_ms", s.median}, {"mean_ms", s.mean},
          {"std_ms", s.std},  {"min_ms", s.min},       {"max_ms", s.max}};
}

// The main map's keyframes with their masks; writes the masks (keyframe_masks/) and the dense map
// when asked for (summary.keyframe_masks, summary.dense).
void WriteKeyframeProducts(const RgbdSource& dataset, const Settings& settings,
                           const RunOptions& options, const SlamSystem& slam,
                           const KeyframeMasks& masks, bool segmented, RunSummary& summary) {
  namespace fs = std::filesystem;
  if (!(options.keyframe_masks && segmented) && options.dense_map.empty()) return;
  size_t loaded = 0;  // keyframes of a map loaded from another session (--load-map)
  const std::vector<DenseKeyframe> keyframes =
      MatchKeyframes(dataset, slam.KeyFrameTrajectory(), masks, &loaded);
  if (options.keyframe_masks && segmented) {
    KeyframeMasks kept;
    for (const DenseKeyframe& kf : keyframes) {
      if (!kf.exclude_png.empty()) kept[kf.frame] = kf.exclude_png;
    }
    WriteKeyframeMasks((fs::path(options.out_dir) / "keyframe_masks").string(), kept);
    summary.keyframe_masks = kept.size();
  }
  if (options.dense_map.empty()) return;
  summary.dense.not_in_source = loaded;
  if (loaded > 0) {
    spdlog::warn("dense map: {} keyframes of the loaded map are not frames of {}: left out", loaded,
                 dataset.name());
  }
  const TsdfVolume volume = FuseKeyframes(dataset, settings.camera, keyframes, options.dense,
                                          &summary.dense, options.dense_progress);
  WriteDenseMap(volume, options.dense_map, &summary.dense);
}

void WriteOutputs(const RgbdSource& dataset, const Settings& settings, const RunOptions& options,
                  const SlamSystem& slam, const KeyframeMasks& masks, bool segmented,
                  RunSummary& summary) {
  namespace fs = std::filesystem;
  const fs::path out(options.out_dir);
  const std::string header = "detslam trajectory (world_from_camera) of " + dataset.name() +
                             "\nsettings: " + settings.source;
  // The main map's frames go to trajectory.txt; maps that never merged into it to files of their
  // own (never mixed in). Those of an earlier run in the same folder are removed first.
  const MapTrajectories trajectories = slam.FrameTrajectories();
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(out, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("trajectory_map", 0) == 0 && entry.path().extension() == ".txt")
      fs::remove(entry.path(), ec);
  }
  std::map<double, int> final_map;  // stamp -> map that holds the frame at the end
  summary.tracked_main = 0;
  for (const auto& [map_id, trajectory] : trajectories.by_map) {
    for (const auto& p : trajectory) final_map[p.stamp.Seconds()] = map_id;
    if (map_id == trajectories.main_map) {
      summary.tracked_main = trajectory.size();
      continue;
    }
    WriteTumTrajectory((out / ("trajectory_map" + std::to_string(map_id) + ".txt")).string(),
                       trajectory,
                       header + "\nmap " + std::to_string(map_id) +
                           " of the atlas (never merged into the main map: its own frame)");
  }
  summary.maps_left = static_cast<int>(trajectories.by_map.size());
  WriteTumTrajectory((out / "trajectory.txt").string(),
                     trajectories.main_map < 0 ? Trajectory()
                                               : trajectories.by_map.at(trajectories.main_map),
                     header);
  WriteTumTrajectory((out / "keyframes.txt").string(), slam.KeyFrameTrajectory(),
                     "detslam keyframes of " + dataset.name());
  std::vector<Eigen::Vector3d> points;  // of the main map (the others are in frames of their own)
  {
    const MapStore::ReadAccess map = slam.ReadMap();
    for (const auto& [id, lm] : map->landmarks()) {
      (void)id;
      if (!lm.observations.empty() &&
          map->MapOf(lm.observations.begin()->first) == trajectories.main_map)
        points.push_back(lm.position);
    }
  }
  WritePointCloudPly((out / "map.ply").string(), points, {});
  if (!options.save_map.empty()) summary.map_file_bytes = slam.SaveMap(options.save_map);
  WriteKeyframeProducts(dataset, settings, options, slam, masks, segmented, summary);
  nlohmann::json j;
  j["dataset"] = dataset.name();
  j["settings"] = settings.source;
  j["effective_settings"] = EffectiveSettingsJson(settings, options);
  j["mode"] = options.threaded ? (options.mapping_thread ? "threaded (mapping thread)" : "threaded")
                               : "sequential";
  j["camera"] = {{"fx", settings.camera.fx},
                 {"fy", settings.camera.fy},
                 {"cx", settings.camera.cx},
                 {"cy", settings.camera.cy},
                 {"depth_map_factor", settings.camera.depth_map_factor},
                 {"bf", settings.camera.bf},
                 {"th_depth", settings.camera.th_depth},
                 {"disparity_sigma", settings.camera.disparity_sigma}};
  j["orb"] = {{"num_features", options.slam.orb.num_features},
              {"scale_factor", options.slam.orb.scale_factor},
              {"num_levels", options.slam.orb.num_levels},
              {"ini_th_fast", options.slam.orb.ini_th_fast},
              {"min_th_fast", options.slam.orb.min_th_fast}};
  j["seed"] = options.slam.tracker.seed;
  j["interrupted"] = summary.interrupted;
  j["frames"] = summary.frames;
  nlohmann::json skipped = nlohmann::json::array();
  for (const FrameReport& r : summary.reports) {
    if (!r.skipped.empty()) skipped.push_back({{"frame", r.index}, {"reason", r.skipped}});
  }
  j["skipped_frames"] = skipped;
  j["frames_tracked"] = summary.tracked;
  j["tracked_fraction"] = summary.TrackedFraction();
  j["keyframes"] = summary.keyframes;
  j["map_points"] = summary.landmarks;
  j["relocalizations"] = summary.relocalizations;
  j["frames_in_main_map"] = summary.tracked_main;
  nlohmann::json lost = nlohmann::json::array();  // stretches of frames without a pose
  for (size_t i = 0; i < summary.reports.size(); ++i) {
    if (summary.reports[i].tracking.pose_valid) continue;
    size_t k = i;
    while (k + 1 < summary.reports.size() && !summary.reports[k + 1].tracking.pose_valid) ++k;
    lost.push_back({{"first_frame", summary.reports[i].index},
                    {"last_frame", summary.reports[k].index},
                    {"frames", k - i + 1}});
    i = k;
  }
  nlohmann::json merges = nlohmann::json::array();
  for (const LoopRecord& r : summary.loop_records) {
    if (r.merge)
      merges.push_back({{"frame", r.frame}, {"from", r.merged_from}, {"into", r.merged_into}});
  }
  nlohmann::json frames_by_map = nlohmann::json::object();
  for (const auto& [map_id, trajectory] : trajectories.by_map)
    frames_by_map[std::to_string(map_id)] = trajectory.size();
  j["maps"] = {{"main", trajectories.main_map},
               {"started", summary.maps_started},
               {"merged", summary.maps_merged},
               {"left", summary.maps_left},
               {"frames_by_map", frames_by_map},
               {"merges", merges},
               {"lost_stretches", lost}};
  j["loops_closed"] = summary.loops;
  nlohmann::json loops = nlohmann::json::array();
  for (const LoopRecord& r : summary.loop_records) {  // also those of a mapping thread
    loops.push_back({{"frame", r.frame},
                     {"keyframe", r.keyframe},
                     {"candidate_keyframe", r.candidate},
                     {"candidate_frame", r.candidate_frame},
                     {"inliers", r.inliers},
                     {"agreeing_keyframes", r.agreeing},
                     {"correction_m", r.correction_m},
                     {"merge", r.merge}});
  }
  j["loops"] = loops;
  const LoopDetectionStats& ld = summary.loop_detection;
  j["loop_detection"] = {{"candidates", ld.candidates},
                         {"enough_matches", ld.enough_matches},
                         {"rigid_ransac", ld.rigid_ransac},
                         {"verified", ld.verified},
                         {"pending_confirmed", ld.pending_confirmed},
                         {"pending_dropped", ld.pending_dropped},
                         {"revisits", ld.revisits}};
  j["global_ba"] = {{"runs", summary.global_ba_runs}, {"stopped", summary.global_ba_stopped}};
  if (!options.save_map.empty())
    j["map_file"] = {{"path", options.save_map}, {"bytes", summary.map_file_bytes}};
  if (!options.load_map.empty()) {
    j["loaded_map"] = {{"path", options.load_map},
                       {"keyframes", summary.loaded_keyframes},
                       {"map_points", summary.loaded_landmarks},
                       {"load_ms", summary.map_load_ms},
                       {"localization", options.slam.localization}};
  }
  if (segmented && options.keyframe_masks) j["keyframe_masks"] = summary.keyframe_masks;
  if (!options.dense_map.empty()) {
    const DenseMapStats& d = summary.dense;
    j["dense_map"] = {{"path", options.dense_map},
                      {"voxel_m", options.dense.voxel_m},
                      {"truncation_m", options.dense.truncation_m},
                      {"depth_range_m", {options.dense.min_depth_m, options.dense.max_depth_m}},
                      {"min_weight", options.dense.min_weight},
                      {"carve", options.dense.carve},
                      {"keyframes_fused", d.keyframes},
                      {"keyframes_unreadable", d.unreadable},
                      {"keyframes_not_in_source", d.not_in_source},
                      {"keyframes_masked", summary.keyframe_masks},
                      {"points", d.points},
                      {"blocks", d.blocks},
                      {"memory_mb", d.memory_mb},
                      {"fusion_s", d.fusion_s},
                      {"extraction_s", d.extraction_s}};
  }
  j["vocabulary"] = slam.vocabulary_path();
  j["wall_s"] = summary.wall_s;
  j["segmenter"] = summary.segmenter.empty() ? "none" : summary.segmenter;
  const DetSlamOptions& dyn = options.slam.dynamic;
  j["dynamic_filter"] = {{"classes", dyn.filter.dynamic_classes},
                         {"alpha", dyn.filter.alpha},
                         {"depth_step", dyn.filter.depth_step},
                         {"mask_dilation_px", dyn.filter.mask_dilation_px},
                         {"premask", dyn.premask},
                         {"memory_frames", dyn.memory_frames},
                         {"geometric_check", dyn.geometric.enabled},
                         {"segment_every", dyn.segment_every}};
  j["timings"] = {{"segmentation", StatsJson(summary.segmentation)},
                  {"extraction", StatsJson(summary.extraction)},
                  {"tracking", StatsJson(summary.tracking)},
                  {"local_mapping_per_keyframe", StatsJson(summary.mapping)},
                  {"total_per_frame", StatsJson(summary.total)}};
  nlohmann::json per_frame = nlohmann::json::array();
  for (const FrameReport& r : summary.reports) {
    auto fm = final_map.find(r.stamp.Seconds());
    per_frame.push_back({{"index", r.index},
                         {"map", r.map_id},  // when tracked
                         {"final_map", r.tracking.pose_valid && fm != final_map.end() ? fm->second
                                                                                      : -1},
                         {"stamp", r.stamp.Seconds()},
                         {"state", r.skipped.empty() ? ToString(r.tracking.state) : "skipped"},
                         {"tracked", r.tracking.pose_valid},
                         {"method", r.tracking.method},
                         {"inliers", r.tracking.num_inliers},
                         {"keyframe", r.keyframe},
                         {"loop_closed", r.loop_closed},
                         {"keypoints", r.num_keypoints},
                         {"map_keyframes", r.map_keyframes},
                         {"map_points", r.map_points},
                         {"dynamic_instances", r.dynamic_instances},
                         {"rejected_keypoints", r.rejected_keypoints},
                         {"geometric_rejected", r.tracking.geometric_rejected},
                         {"segmentation_ms", r.segmentation_ms},
                         {"extraction_ms", r.timings.extraction_ms},
                         {"tracking_ms", r.timings.tracking_ms},
                         {"mapping_ms", r.timings.mapping_ms}});
  }
  j["per_frame"] = per_frame;
  WriteFileAtomically((out / "run.json").string(),
                      [&](std::ostream& os) { os << j.dump(1) << "\n"; });
}

}  // namespace

SlamOptions SlamOptionsFromSettings(const Settings& settings, uint64_t seed) {
  SlamOptions o = ResolveSettings(settings).run.slam;  // detslam's own keys (settings_keys.cc)
  o.orb.num_features = settings.orb.n_features;
  o.orb.scale_factor = settings.orb.scale_factor;
  o.orb.num_levels = settings.orb.n_levels;
  o.orb.ini_th_fast = settings.orb.ini_th_fast;
  o.orb.min_th_fast = settings.orb.min_th_fast;
  o.tracker.seed = seed;  // relocalisation RANSAC
  o.loop.seed = seed;     // loop verification RANSAC
  o.tracker.max_frames_between_keyframes =
      std::max(1, static_cast<int>(std::lround(settings.camera.fps)));
  return o;
}

namespace {

// Creates `dir` and checks that a file can be written in it, so that a run whose outputs could not
// be written fails before its first frame rather than after its last.
void CheckWritableFolder(const std::string& dir, const std::string& what) {
  namespace fs = std::filesystem;
  const fs::path folder = dir.empty() ? fs::path(".") : fs::path(dir);
  std::error_code ec;
  fs::create_directories(folder, ec);
  if (ec) throw InputError(folder.string(), 0, "cannot create the " + what + ": " + ec.message());
  const fs::path probe = folder / ".detslam_write_probe";
  {
    std::ofstream out(probe, std::ios::binary | std::ios::trunc);
    out << "probe\n";
    out.flush();
    if (!out) throw InputError(folder.string(), 0, "cannot write in the " + what);
  }
  fs::remove(probe, ec);
}

void CheckOutputs(const RunOptions& options) {
  CheckWritableFolder(options.out_dir, "output folder");
  if (!options.save_map.empty()) {
    CheckWritableFolder(std::filesystem::path(options.save_map).parent_path().string(),
                        "folder of the map file (--save-map)");
  }
  if (!options.dense_map.empty()) {
    CheckWritableFolder(std::filesystem::path(options.dense_map).parent_path().string(),
                        "folder of the dense map (--dense-map)");
    std::string error;
    if (!options.dense.Check(&error)) throw InputError("dense map options: " + error);
  }
}

bool StopRequested(const RunOptions& options) {
  return options.stop != nullptr && options.stop->load();
}

// While it lives, watches RunOptions::stop (every 20 ms) and, once it is set, interrupts the SLAM
// system (a global BA running in the calling thread or its own stops) and calls `on_stop` (e.g.
// closing the queues between threaded stages). Does nothing without a stop flag.
class StopWatcher {
 public:
  StopWatcher(const RunOptions& options, SlamSystem* slam, std::function<void()> on_stop = {}) {
    if (options.stop == nullptr) return;
    thread_ = std::thread([this, flag = options.stop, slam, on_stop = std::move(on_stop)] {
      std::unique_lock<std::mutex> lock(mutex_);
      while (!done_) {
        if (flag->load()) {
          slam->Interrupt();
          if (on_stop) on_stop();
          return;
        }
        wake_.wait_for(lock, std::chrono::milliseconds(20));
      }
    });
  }
  ~StopWatcher() {
    if (!thread_.joinable()) return;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      done_ = true;
    }
    wake_.notify_all();
    thread_.join();
  }
  StopWatcher(const StopWatcher&) = delete;
  StopWatcher& operator=(const StopWatcher&) = delete;

 private:
  std::mutex mutex_;
  std::condition_variable wake_;
  bool done_ = false;
  std::thread thread_;
};

// Collects per-frame reports and turns them into the summary and the output files.
class RunRecorder {
 public:
  RunRecorder(size_t total, const ProgressFn& progress) : total_(total), progress_(progress) {}

  void Add(const FrameReport& r) {
    ++summary_.frames;
    if (r.tracking.pose_valid) ++summary_.tracked;
    if (r.tracking.relocalized) ++summary_.relocalizations;
    if (r.tracking.method == "init" || r.tracking.new_map) ++summary_.maps_started;
    if (r.segmentation_ms > 0) seg_.push_back(r.segmentation_ms);
    ext_.push_back(r.timings.extraction_ms);
    trk_.push_back(r.timings.tracking_ms);
    total_ms_.push_back(r.segmentation_ms + r.timings.extraction_ms + r.timings.tracking_ms +
                        r.timings.mapping_ms);
    summary_.reports.push_back(r);
    if (progress_) progress_(summary_.frames, total_, r);
  }

  // A frame whose images could not be read (r.skipped says why): no pose, listed in run.json
  // (skipped_frames).
  void AddSkipped(const FrameReport& r) {
    constexpr size_t kWarnings = 10;
    if (summary_.skipped < kWarnings) {
      spdlog::warn("frame {} skipped: {}", r.index, r.skipped);
    } else if (summary_.skipped == kWarnings) {
      spdlog::warn("further unreadable frames are skipped without a warning (all in run.json)");
    }
    ++summary_.skipped;
    ++summary_.frames;
    summary_.reports.push_back(r);
    if (progress_) progress_(summary_.frames, total_, r);
  }

  // A keyframe's pixels removed by the Det-SLAM stage (its instances' masks and depth step), kept
  // PNG-encoded for keyframe_masks/ and the dense map; nothing when the frame was not segmented
  // or nothing was removed.
  void AddKeyframeMask(const RunOptions& options, int64_t frame,
                       const std::vector<Instance>& instances, const cv::Mat& depth_m) {
    if (instances.empty() || (!options.keyframe_masks && options.dense_map.empty())) return;
    const cv::Mat mask =
        DynamicIgnoreMask(instances, depth_m, depth_m.size(), options.slam.dynamic.filter);
    if (cv::countNonZero(mask) > 0) masks_[static_cast<size_t>(frame)] = EncodeKeyframeMask(mask);
  }

  // Starts `slam` from options.load_map (if any); recorded in the summary.
  void LoadMap(const RunOptions& options, SlamSystem* slam) {
    if (options.load_map.empty()) return;
    const auto t0 = std::chrono::steady_clock::now();
    const MapFileInfo info = slam->LoadMap(options.load_map);
    summary_.map_load_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    summary_.loaded_keyframes = info.keyframes;
    summary_.loaded_landmarks = info.landmarks;
  }

  RunSummary Finish(const RgbdSource& dataset, const Settings& settings, const RunOptions& options,
                    SlamSystem& slam, std::chrono::steady_clock::time_point start,
                    const Segmenter* segmenter) {
    if (segmenter != nullptr) summary_.segmenter = segmenter->name();
    if (summary_.frames > 0 && summary_.skipped == summary_.frames) {
      throw InputError("no frame of " + dataset.name() + " could be read; the first: " +
                       summary_.reports.front().skipped);
    }
    summary_.segmentation = ComputeErrorStats(seg_);
    slam.WaitForGlobalBundleAdjustment();
    summary_.interrupted = StopRequested(options);  // also while the last global BA ran
    if (summary_.interrupted)
      spdlog::warn("run interrupted after {} of {} frames: writing the outputs so far",
                   summary_.frames, total_);
    summary_.loops = static_cast<size_t>(slam.loops_closed());
    summary_.maps_merged = slam.maps_merged();
    summary_.loop_records = slam.loops();
    summary_.loop_detection = slam.loop_detection_stats();
    summary_.global_ba_runs = slam.global_ba_runs();
    summary_.global_ba_stopped = slam.global_ba_stopped();
    {
      const MapStore::ReadAccess map = slam.ReadMap();
      summary_.keyframes = map->NumKeyFrames();
      summary_.landmarks = map->NumLandmarks();
    }
    summary_.extraction = ComputeErrorStats(ext_);
    summary_.tracking = ComputeErrorStats(trk_);
    summary_.mapping = ComputeErrorStats(slam.mapping_times_ms());
    summary_.total = ComputeErrorStats(total_ms_);
    summary_.wall_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    WriteOutputs(dataset, settings, options, slam, masks_, segmenter != nullptr, summary_);
    return summary_;
  }

 private:
  size_t total_;
  ProgressFn progress_;
  RunSummary summary_;
  std::vector<double> seg_, ext_, trk_, total_ms_;
  KeyframeMasks masks_;
};

size_t FrameCount(const RgbdSource& dataset, const RunOptions& options) {
  size_t n = dataset.size();
  if (options.max_frames >= 0) n = std::min(n, static_cast<size_t>(options.max_frames));
  return n;
}

}  // namespace

namespace {

struct LoadedFrame {
  int64_t index = 0;
  std::string unreadable;  // why its images could not be read (then nothing else is set)
  RgbdImages images;
  std::vector<Instance> instances;
  bool segmented = false;
  double segmentation_ms = 0;
};

LoadedFrame LoadAndSegment(const RgbdSource& dataset, const Settings& settings, size_t i,
                           SlamSystem* slam) {
  LoadedFrame f;
  f.index = static_cast<int64_t>(i);
  try {
    f.images = dataset.Load(i, settings.camera);
  } catch (const InputError& e) {
    f.unreadable = e.what();
    return f;
  }
  SegmenterInput in;
  in.index = f.index;
  in.stamp = dataset.stamp(i);
  in.bgr = f.images.bgr;
  in.depth_m = f.images.depth_m;
  FrameInstances dynamic = slam->SegmentFrame(in, f.images.gray);
  f.instances = std::move(dynamic.instances);
  f.segmented = dynamic.segmented;
  f.segmentation_ms = dynamic.segmentation_ms;
  return f;
}

// The report of a frame whose images could not be read (f.unreadable is set).
FrameReport SkippedReport(const RgbdSource& dataset, const LoadedFrame& f) {
  FrameReport r;
  r.index = f.index;
  r.stamp = dataset.stamp(static_cast<size_t>(f.index));
  r.skipped = f.unreadable;
  return r;
}

Frame Extract(const SlamSystem& slam, const RgbdSource& dataset, const LoadedFrame& f,
              FrameReport* report) {
  report->segmentation_ms = f.segmentation_ms;
  return slam.ExtractFrame(f.index, dataset.stamp(static_cast<size_t>(f.index)),
                           f.images.gray, f.images.depth_m, cv::Mat(), report,
                           f.segmented ? &f.instances : nullptr);
}

}  // namespace

RunSummary RunSequential(const RgbdSource& dataset, const Settings& settings,
                         const RunOptions& options, const ProgressFn& progress,
                         Segmenter* segmenter) {
  const auto start = std::chrono::steady_clock::now();
  CheckOutputs(options);
  SlamSystem slam(settings.camera, options.slam, segmenter);
  const size_t n = FrameCount(dataset, options);
  RunRecorder recorder(n, progress);
  recorder.LoadMap(options, &slam);
  const StopWatcher watcher(options, &slam);
  for (size_t i = 0; i < n && !StopRequested(options); ++i) {
    const LoadedFrame loaded = LoadAndSegment(dataset, settings, i, &slam);
    if (!loaded.unreadable.empty()) {
      recorder.AddSkipped(SkippedReport(dataset, loaded));
      continue;
    }
    FrameReport report;
    Frame frame = Extract(slam, dataset, loaded, &report);
    const KeyFrameId kf = slam.TrackFrame(std::move(frame), &report);
    if (kf != kNoKeyFrame) {
      recorder.AddKeyframeMask(options, loaded.index, loaded.instances, loaded.images.depth_m);
      slam.MapKeyFrame(kf, &report);
    }
    recorder.Add(report);
  }
  return recorder.Finish(dataset, settings, options, slam, start, segmenter);
}

RunSummary RunThreaded(const RgbdSource& dataset, const Settings& settings,
                       const RunOptions& options, const ProgressFn& progress,
                       Segmenter* segmenter) {
  const auto start = std::chrono::steady_clock::now();
  CheckOutputs(options);
  SlamOptions slam_options = options.slam;
  slam_options.global_ba_thread = options.mapping_thread;  // nothing waits for it then
  SlamSystem slam(settings.camera, slam_options, segmenter);
  const size_t n = FrameCount(dataset, options);
  RunRecorder recorder(n, progress);
  recorder.LoadMap(options, &slam);
  struct Extracted {
    Frame frame;
    FrameReport report;
    std::vector<Instance> instances;  // for the keyframe masks
    cv::Mat depth_m;
  };
  BoundedQueue<LoadedFrame> loaded(options.queue_capacity);
  BoundedQueue<Extracted> extracted(options.queue_capacity);
  BoundedQueue<KeyFrameId> keyframes(8);
  const auto close_queues = [&] {
    loaded.Close();
    extracted.Close();
    keyframes.Close();
  };
  StageThreads stages(close_queues);
  // A stop drops the frames and keyframes still queued: every stage ends after its current item.
  const StopWatcher watcher(options, &slam, close_queues);
  stages.Start(
      "loading",
      [&] {
        for (size_t i = 0; i < n && !StopRequested(options); ++i) {
          if (!loaded.Push(LoadAndSegment(dataset, settings, i, &slam))) break;
        }
      },
      [&] { loaded.Close(); });
  stages.Start(
      "extraction",
      [&] {
        while (std::optional<LoadedFrame> f = loaded.Pop()) {
          if (StopRequested(options)) break;
          Extracted e;
          if (!f->unreadable.empty()) {
            e.report = SkippedReport(dataset, *f);
          } else {
            e.frame = Extract(slam, dataset, *f, &e.report);
            e.instances = std::move(f->instances);
            e.depth_m = f->images.depth_m;
          }
          if (!extracted.Push(std::move(e))) break;
        }
      },
      [&] { extracted.Close(); });
  if (options.mapping_thread) {
    stages.Start("local mapping", [&] {
      while (std::optional<KeyFrameId> kf = keyframes.Pop()) {
        if (StopRequested(options)) break;  // the keyframe stays in the map, not locally mapped
        FrameReport unused;
        slam.MapKeyFrame(*kf, &unused);
      }
    });
  }
  stages.RunHere(
      "tracking",
      [&] {
        while (std::optional<Extracted> e = extracted.Pop()) {
          if (StopRequested(options)) break;
          if (!e->report.skipped.empty()) {
            recorder.AddSkipped(e->report);
            continue;
          }
          const KeyFrameId kf = slam.TrackFrame(std::move(e->frame), &e->report);
          if (kf != kNoKeyFrame) {
            recorder.AddKeyframeMask(options, e->report.index, e->instances, e->depth_m);
            if (!options.mapping_thread) {
              slam.MapKeyFrame(kf, &e->report);
            } else if (!keyframes.Push(kf)) {
              break;  // the mapping stage failed
            }
          }
          recorder.Add(e->report);
        }
      },
      [&] { keyframes.Close(); });
  stages.Join();
  return recorder.Finish(dataset, settings, options, slam, start, segmenter);
}

RunSummary Run(const RgbdSource& dataset, const Settings& settings, const RunOptions& options,
               const ProgressFn& progress, Segmenter* segmenter) {
  return options.threaded ? RunThreaded(dataset, settings, options, progress, segmenter)
                          : RunSequential(dataset, settings, options, progress, segmenter);
}

}  // namespace detslam
