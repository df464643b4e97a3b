#include "detslam/pipeline/runner.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <filesystem>
#include <fstream>
#include <functional>
#include <future>
#include <mutex>
#include <numeric>
#include <optional>
#include <thread>

#include <opencv2/core/utility.hpp>

#include "detslam/core/check.h"
#include "detslam/core/cpu_load.h"
#include "detslam/dynamic/mask_carrier.h"
#include "detslam/pipeline/bounded_queue.h"
#include "detslam/pipeline/keyframe_mask_recorder.h"
#include "detslam/pipeline/run_outputs.h"
#include "detslam/pipeline/settings_keys.h"
#include "detslam/pipeline/stage_threads.h"

namespace detslam {

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
  RunRecorder(size_t total, const ProgressFn& progress, const RunOptions& options)
      : total_(total),
        progress_(progress),
        mask_recorder_(options.slam.dynamic.filter, options.slam.dynamic.memory_frames) {}

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
    if (r.latency_ms >= 0) latency_.push_back(r.latency_ms);
    if (r.mask_age >= 0) mask_age_.push_back(r.mask_age);
    if (r.keyframe_deferred) ++summary_.keyframes_deferred;
    if (r.keyframe_stale_masks) ++summary_.keyframes_stale_masks;
    if (r.keyframe_cleaned >= 0) {
      ++summary_.keyframes_cleaned;
      summary_.keypoints_cleaned += static_cast<size_t>(r.keyframe_cleaned);
    }
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

  // Every frame's instances, for the keyframe masks (keyframe_masks/ and the dense map).
  void AddFrameMasks(const RunOptions& options, int64_t frame, bool keyframe,
                     const std::vector<Instance>& instances, const cv::Mat& depth_m) {
    if (!options.keyframe_masks && options.dense_map.empty()) return;
    mask_recorder_.AddFrame(frame, keyframe, instances, depth_m);
  }

  // Camera-rate mode: frames the camera offered, those it dropped, and seconds from its start.
  void SetCamera(size_t offered, std::vector<int64_t> dropped, double camera_s) {
    summary_.offered = offered;
    summary_.dropped_frames = std::move(dropped);
    summary_.camera_s = camera_s;
  }

  // Asynchronous segmentation: the segmenter's time on each frame it segmented (they replace the
  // per-frame times, which are then those of carrying the masks).
  void SetAsyncSegmentation(const std::vector<double>& detection_ms, double headroom_wait_ms = 0) {
    summary_.async_segmentation = true;
    summary_.frames_segmented = detection_ms.size();
    summary_.headroom_wait_ms = headroom_wait_ms;
    seg_ = detection_ms;
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
      throw InputError("no frame of " + dataset.name() +
                       " could be read; the first: " + summary_.reports.front().skipped);
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
    summary_.keyframes_mapped_in_burst = slam.keyframes_mapped_in_burst();
    summary_.global_ba_applied_after_frames = slam.global_ba_applied_after_frames();
    {
      const MapStore::ReadAccess map = slam.ReadMap();
      summary_.keyframes = map->NumKeyFrames();
      summary_.landmarks = map->NumLandmarks();
    }
    summary_.extraction = ComputeErrorStats(ext_);
    summary_.tracking = ComputeErrorStats(trk_);
    summary_.mapping = ComputeErrorStats(slam.mapping_times_ms());
    summary_.loop_closing = ComputeErrorStats(slam.loop_closing_times_ms());
    summary_.loop_thread = slam.loop_thread();
    summary_.total = ComputeErrorStats(total_ms_);
    summary_.latency = ComputeErrorStats(latency_);
    summary_.latency_p99_ms = Percentile(latency_, 99);
    summary_.mask_age = ComputeErrorStats(mask_age_);
    summary_.wall_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    WriteRunOutputs(dataset, settings, options, slam, mask_recorder_.Finish(), segmenter != nullptr,
                    summary_);
    return summary_;
  }

 private:
  size_t total_;
  ProgressFn progress_;
  RunSummary summary_;
  std::vector<double> seg_, ext_, trk_, total_ms_, latency_, mask_age_;
  KeyframeMaskRecorder mask_recorder_;
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
  int64_t mask_source = -1;  // asynchronous segmentation: where its masks come from, their age
  int mask_age = -1;
  std::chrono::steady_clock::time_point arrival;  // camera-rate mode: when the camera offered it
};

LoadedFrame LoadFrame(const RgbdSource& dataset, const Settings& settings, size_t i) {
  LoadedFrame f;
  f.index = static_cast<int64_t>(i);
  try {
    f.images = dataset.Load(i, settings.camera);
  } catch (const InputError& e) {
    f.unreadable = e.what();
  }
  return f;
}

SegmenterInput SegmentationInput(const RgbdSource& dataset, const LoadedFrame& f) {
  SegmenterInput in;
  in.index = f.index;
  in.stamp = dataset.stamp(static_cast<size_t>(f.index));
  in.bgr = f.images.bgr;
  in.depth_m = f.images.depth_m;
  return in;
}

// The Det-SLAM stage's segmentation of a loaded frame (nothing for an unreadable one).
void Segment(const RgbdSource& dataset, SlamSystem* slam, LoadedFrame* f) {
  if (!f->unreadable.empty()) return;
  FrameInstances dynamic = slam->SegmentFrame(SegmentationInput(dataset, *f), f->images.gray);
  f->instances = std::move(dynamic.instances);
  f->segmented = dynamic.segmented;
  f->segmentation_ms = dynamic.segmentation_ms;
}

LoadedFrame LoadAndSegment(const RgbdSource& dataset, const Settings& settings, size_t i,
                           SlamSystem* slam) {
  LoadedFrame f = LoadFrame(dataset, settings, i);
  Segment(dataset, slam, &f);
  return f;
}

// Camera-rate mode: offers the frames at their timestamps (relative to the first one's, from
// the camera's start) into `camera`, which holds one frame; a frame not taken before the next
// arrives is dropped (its index appended to *dropped). A camera delivers decoded images: the
// first frames, up to options.camera_preload_mb of decoded images, are read and decoded before
// the camera starts (*camera_start); the frames after those are read on time, in this thread.
// Returns the number offered.
size_t OfferAtCameraRate(const RgbdSource& dataset, const Settings& settings, size_t n,
                         const RunOptions& options, BoundedQueue<LoadedFrame>* camera,
                         std::vector<int64_t>* dropped,
                         std::chrono::steady_clock::time_point* camera_start) {
  using Clock = std::chrono::steady_clock;
  std::deque<LoadedFrame> preloaded;
  const double budget = static_cast<double>(options.camera_preload_mb) * 1024 * 1024;
  double bytes = 0;
  while (preloaded.size() < n && bytes < budget && !StopRequested(options)) {
    preloaded.push_back(LoadFrame(dataset, settings, preloaded.size()));
    const RgbdImages& im = preloaded.back().images;
    bytes += static_cast<double>(im.bgr.total() * im.bgr.elemSize() + im.gray.total() * im.gray.elemSize() +
                                 im.depth_m.total() * im.depth_m.elemSize()) + 1024;
  }
  const size_t preloaded_frames = preloaded.size();
  const Clock::time_point start = *camera_start = Clock::now();
  const double first = n > 0 ? dataset.stamp(0).Seconds() : 0.0;
  Clock::time_point previous = start;
  size_t offered = 0;
  for (size_t i = 0; i < n && !StopRequested(options); ++i) {
    LoadedFrame f;
    if (i < preloaded_frames) {
      f = std::move(preloaded.front());
      preloaded.pop_front();
    } else {
      f = LoadFrame(dataset, settings, i);
    }
    const double after = std::max(0.0, dataset.stamp(i).Seconds() - first);
    const Clock::time_point due = std::max(
        previous,
        start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(after)));
    // In steps, so that a stop is seen within 20 ms.
    for (Clock::time_point now = Clock::now(); now < due && !StopRequested(options);
         now = Clock::now())
      std::this_thread::sleep_until(std::min(due, now + std::chrono::milliseconds(20)));
    f.arrival = previous = std::max(due, Clock::now());
    std::optional<LoadedFrame> old;
    if (!camera->PushDroppingOldest(std::move(f), &old)) break;
    if (old) dropped->push_back(old->index);
    ++offered;
  }
  return offered;
}

// OpenCV's thread count (cv::setNumThreads) for a scope: `n` > 0 sets it, 0 leaves it; the count
// before is restored at the end. A count already in force is left alone (OpenCV 4.6 with TBB
// makes a worker arena even for 1 thread; getNumThreads() after setNumThreads(0) reports the
// pool's size, not 0, so a restore is not always exact).
class OpenCvThreads {
 public:
  explicit OpenCvThreads(int n) : before_(cv::getNumThreads()), set_(n > 0 && n != before_) {
    if (set_) cv::setNumThreads(n);
  }
  ~OpenCvThreads() {
    if (set_) cv::setNumThreads(before_);
  }
  OpenCvThreads(const OpenCvThreads&) = delete;
  OpenCvThreads& operator=(const OpenCvThreads&) = delete;

 private:
  int before_;
  bool set_;
};

// The report of a frame whose images could not be read (f.unreadable is set).
FrameReport SkippedReport(const RgbdSource& dataset, const LoadedFrame& f) {
  FrameReport r;
  r.index = f.index;
  r.stamp = dataset.stamp(static_cast<size_t>(f.index));
  r.skipped = f.unreadable;
  return r;
}

// Tells the run's observer (if any) about a frame just finished.
void Observe(RunObserver* observer, const SlamSystem& slam, const FrameReport& report,
             const cv::Mat* bgr = nullptr, const std::vector<Instance>* instances = nullptr,
             const Frame* tracked = nullptr) {
  if (observer == nullptr) return;
  ObservedFrame f;
  f.report = &report;
  f.bgr = bgr;
  f.instances = instances;
  f.frame = tracked;
  observer->OnFrame(f, slam);
}

RunSummary Finish(RunRecorder& recorder, const RgbdSource& dataset, const Settings& settings,
                  const RunOptions& options, SlamSystem& slam,
                  std::chrono::steady_clock::time_point start, const Segmenter* segmenter) {
  RunSummary summary = recorder.Finish(dataset, settings, options, slam, start, segmenter);
  if (options.observer) options.observer->OnFinish(summary, slam);
  return summary;
}

// The SLAM options of a run whose masks come asynchronously (RunOptions::
// camera_rate_region_frames).
SlamOptions CameraRateMasks(const RunOptions& options) {
  SlamOptions slam = options.slam;
  slam.dynamic.geometric.region_frames = options.camera_rate_region_frames;
  return slam;
}

// Gives a frame the instances a MaskCarrier carried to it (asynchronous segmentation).
void UseCarried(CarriedInstances c, LoadedFrame* f) {
  f->instances = std::move(c.instances);
  f->segmented = true;
  f->segmentation_ms = c.carry_ms;
  f->mask_source = c.source;
  f->mask_age = c.age;
}

// Sequential mode, RunOptions::simulated_detector_frames: the camera-rate mode's asynchronous
// segmentation with a detector that takes a fixed number of input frames per frame it segments,
// so that its mask timing is deterministic. The detector starts on the newest frame whenever it is
// free; its result is published before the frame `frames` later is tracked; the first frame waits
// for its own masks.
class SimulatedAsyncSegmentation {
 public:
  SimulatedAsyncSegmentation(int frames, const MaskPropagationOptions& propagation)
      : frames_(frames), carrier_(propagation) {}

  // Frames in input order, readable ones only.
  void Carry(const RgbdSource& dataset, SlamSystem* slam, LoadedFrame* f) {
    if (pending_ && f->index >= pending_->ready) Publish(slam);
    if (!pending_) {
      const FrameInstances d = slam->DetectFrame(SegmentationInput(dataset, *f));
      detection_ms_.push_back(d.segmentation_ms);
      const bool first = carrier_.published() == 0;
      pending_ = Pending{f->index, f->index + (first ? 0 : frames_), f->images.gray,
                         f->images.depth_m, d.instances};
      if (first) Publish(slam);
    }
    if (std::optional<CarriedInstances> c = carrier_.Carry(f->index, f->images.gray))
      UseCarried(std::move(*c), f);
  }

  const std::vector<double>& detection_ms() const { return detection_ms_; }

 private:
  struct Pending {
    int64_t index, ready;
    cv::Mat gray, depth_m;
    std::vector<Instance> instances;
  };
  void Publish(SlamSystem* slam) {
    slam->OfferOwnMasks(pending_->index, pending_->instances, pending_->depth_m);
    carrier_.Publish(pending_->index, pending_->gray, std::move(pending_->instances));
    pending_.reset();
  }

  int frames_;
  MaskCarrier carrier_;
  std::optional<Pending> pending_;  // the detection in progress
  std::vector<double> detection_ms_;
};

// `pyramid`: null, or slam.PrepareExtraction of the frame's image.
Frame Extract(const SlamSystem& slam, const RgbdSource& dataset, const LoadedFrame& f,
              FrameReport* report, const OrbPyramid* pyramid = nullptr) {
  report->segmentation_ms = f.segmentation_ms;
  report->mask_source = f.mask_source;
  report->mask_age = f.mask_age;
  return slam.ExtractFrame(f.index, dataset.stamp(static_cast<size_t>(f.index)), f.images.gray,
                           f.images.depth_m, cv::Mat(), report,
                           f.segmented ? &f.instances : nullptr, pyramid);
}

// SlamSystem::PrepareExtraction with its time.
struct PreparedExtraction {
  OrbPyramid pyramid;
  double ms = 0;
};

}  // namespace

RunSummary RunSequential(const RgbdSource& dataset, const Settings& settings,
                         const RunOptions& options, const ProgressFn& progress,
                         Segmenter* segmenter) {
  const auto start = std::chrono::steady_clock::now();
  CheckOutputs(options);
  const bool simulate = segmenter != nullptr && options.simulated_detector_frames > 0;
  SlamSystem slam(settings.camera, simulate ? CameraRateMasks(options) : options.slam, segmenter);
  const size_t n = FrameCount(dataset, options);
  RunRecorder recorder(n, progress, options);
  recorder.LoadMap(options, &slam);
  const StopWatcher watcher(options, &slam);
  RunObserver* observer = options.observer;
  if (observer) observer->OnStart(n, /*pausable=*/true);
  std::optional<SimulatedAsyncSegmentation> simulated;
  if (simulate)
    simulated.emplace(options.simulated_detector_frames, options.slam.dynamic.propagation);
  for (size_t i = 0; i < n && !StopRequested(options); ++i) {
    if (observer) {
      observer->WaitBeforeFrame(static_cast<int64_t>(i), slam);
      if (StopRequested(options)) break;
    }
    LoadedFrame loaded = simulated ? LoadFrame(dataset, settings, i)
                                   : LoadAndSegment(dataset, settings, i, &slam);
    if (simulated && loaded.unreadable.empty()) simulated->Carry(dataset, &slam, &loaded);
    if (!loaded.unreadable.empty()) {
      const FrameReport report = SkippedReport(dataset, loaded);
      recorder.AddSkipped(report);
      Observe(observer, slam, report);
      continue;
    }
    FrameReport report;
    Frame frame = Extract(slam, dataset, loaded, &report);
    Frame tracked;
    const KeyFrameId kf = slam.TrackFrame(std::move(frame), &report, observer ? &tracked : nullptr);
    recorder.AddFrameMasks(options, loaded.index, kf != kNoKeyFrame, loaded.instances,
                           loaded.images.depth_m);
    if (kf != kNoKeyFrame) slam.MapKeyFrame(kf, &report);
    recorder.Add(report);
    Observe(observer, slam, report, &loaded.images.bgr,
            loaded.segmented ? &loaded.instances : nullptr, &tracked);
  }
  if (simulated) recorder.SetAsyncSegmentation(simulated->detection_ms());
  return Finish(recorder, dataset, settings, options, slam, start, segmenter);
}

RunSummary RunThreaded(const RgbdSource& dataset, const Settings& settings,
                       const RunOptions& options, const ProgressFn& progress,
                       Segmenter* segmenter) {
  const auto start = std::chrono::steady_clock::now();
  CheckOutputs(options);
  const OpenCvThreads cv_threads(options.realtime ? options.camera_rate_opencv_threads : 0);
  // Asynchronous segmentation: the newest frame for the segmentation thread, and its results.
  const bool async = options.realtime && options.async_segmentation && segmenter != nullptr;
  const int mapping_nice = options.mapping_nice >= 0 ? options.mapping_nice : options.background_nice;
  SlamOptions slam_options = async ? CameraRateMasks(options) : options.slam;
  slam_options.global_ba_thread = options.mapping_thread;  // nothing waits for it then
  slam_options.loop_thread = options.mapping_thread && options.loop_thread;
  SlamSystem slam(settings.camera, slam_options, segmenter);
  const size_t n = FrameCount(dataset, options);
  RunRecorder recorder(n, progress, options);
  recorder.LoadMap(options, &slam);
  struct Extracted {
    Frame frame;
    FrameReport report;
    std::vector<Instance> instances;  // for the keyframe masks
    bool segmented = false;
    cv::Mat depth_m;
    cv::Mat bgr;                                    // for the observer (only with one)
    std::chrono::steady_clock::time_point arrival;  // camera-rate mode
  };
  RunObserver* observer = options.observer;
  if (observer) observer->OnStart(n, /*pausable=*/false);
  // At camera rate a frame waits in no queue longer than it must: one frame between stages.
  const size_t capacity = options.realtime ? 1 : options.queue_capacity;
  BoundedQueue<LoadedFrame> camera(1);  // camera-rate mode: the camera's newest frame
  BoundedQueue<LoadedFrame> loaded(capacity);
  BoundedQueue<Extracted> extracted(capacity);
  BoundedQueue<KeyFrameId> keyframes(8);
  // Keyframes local mapping finished, for the loop-closing thread (ids only; the bound is never
  // reached in practice, and a full queue only makes local mapping wait, never a deadlock: local
  // mapping pushes outside its turn, see SlamSystem::loop_thread).
  BoundedQueue<KeyFrameId> to_close(1024);
  BoundedQueue<LoadedFrame> to_segment(1);
  MaskCarrier carrier(options.slam.dynamic.propagation);
  std::vector<double> detection_ms;  // the segmentation thread's until Join
  double headroom_wait_ms = 0;       // the same
  const auto close_queues = [&] {
    camera.Close();
    loaded.Close();
    extracted.Close();
    keyframes.Close();
    to_close.Close();
    to_segment.Close();
    carrier.Close();
  };
  StageThreads stages(close_queues);
  // A stop drops the frames and keyframes still queued: every stage ends after its current item.
  const StopWatcher watcher(options, &slam, close_queues);
  size_t offered = 0;
  std::vector<int64_t> dropped;  // the camera thread's until Join
  std::chrono::steady_clock::time_point camera_start = start;  // the camera thread's until Join
  if (options.realtime && segmenter != nullptr && n > 0) {
    // As a live system would before opening the camera: the networks' first call (allocating
    // their layers) is several times slower than the next ones. The result is not used.
    const LoadedFrame first = LoadFrame(dataset, settings, 0);
    if (first.unreadable.empty()) segmenter->WarmUp(SegmentationInput(dataset, first));
  }
  if (options.realtime) {
    stages.Start(
        "camera",
        [&] {
          offered = OfferAtCameraRate(dataset, settings, n, options, &camera, &dropped, &camera_start);
        },
        [&] { camera.Close(); });
  }
  if (async) {
    stages.Start(
        "segmentation",
        [&] {
          // Asynchronous segmentation runs only at camera rate.
          if (!options.idle_segmentation || !MakeThisThreadIdlePriority())
            LowerThisThreadPriority(options.background_nice);
          CpuHeadroom::Options ho;
          ho.max_busy = options.camera_rate_max_busy;
          ho.max_wait = std::chrono::milliseconds(
              static_cast<int64_t>(options.camera_rate_headroom_max_wait_ms));
          CpuHeadroom headroom(ho);
          while (true) {
            // Waits before taking a frame, so that it takes the newest after the wait.
            headroom_wait_ms += headroom.Wait(options.stop);
            std::optional<LoadedFrame> f = to_segment.Pop();
            if (!f || StopRequested(options)) break;
            FrameInstances d = slam.DetectFrame(SegmentationInput(dataset, *f));
            detection_ms.push_back(d.segmentation_ms);
            slam.OfferOwnMasks(f->index, d.instances, f->images.depth_m);
            carrier.Publish(f->index, f->images.gray, std::move(d.instances));
          }
        },
        [&] { carrier.Close(); });  // no frame waits for masks that will not come
  } else {
    stages.Start(
        options.realtime ? "segmentation" : "loading",
        [&] {
          if (options.realtime) {
            while (std::optional<LoadedFrame> f = camera.Pop()) {
              if (StopRequested(options)) break;
              Segment(dataset, &slam, &*f);
              if (!loaded.Push(std::move(*f))) break;
            }
            return;
          }
          for (size_t i = 0; i < n && !StopRequested(options); ++i) {
            if (!loaded.Push(LoadAndSegment(dataset, settings, i, &slam))) break;
          }
        },
        [&] { loaded.Close(); });
  }
  // Asynchronous segmentation: hands the frame to the segmentation thread (replacing a frame it
  // has not taken yet) and gives the frame the newest masks carried to it. Returns false for a
  // frame not processed (it goes into `not_processed`). The start: the first frame waits for its
  // own masks; with options.first_frame_waits_for_masks it is processed, and the frames that
  // arrived before its masks are not (they would queue behind it); without, it is not processed
  // and the next frame is.
  std::optional<std::chrono::steady_clock::time_point> first_masks;
  std::vector<int64_t> not_processed;  // the extraction thread's until Join
  const auto carry_masks = [&](LoadedFrame* f) -> bool {
    if (first_masks && options.first_frame_waits_for_masks && f->arrival < *first_masks) {
      not_processed.push_back(f->index);
      return false;
    }
    std::optional<LoadedFrame> replaced;
    // The segmentation thread gets images of its own: cv::Mat's reference count lives in OpenCV's
    // (uninstrumented) library, so buffers shared between threads and released last by another
    // thread than the one that read them are reported by ThreadSanitizer (seen in the failing-
    // stage test under load); owning copies leave nothing shared.
    LoadedFrame for_segmentation = *f;
    for_segmentation.images.bgr = f->images.bgr.clone();
    for_segmentation.images.gray = f->images.gray.clone();
    for_segmentation.images.depth_m = f->images.depth_m.clone();
    to_segment.PushDroppingOldest(std::move(for_segmentation), &replaced);
    if (!first_masks) {
      const bool published = carrier.WaitFor(f->index);
      first_masks = std::chrono::steady_clock::now();
      if (published && !options.first_frame_waits_for_masks) {
        not_processed.push_back(f->index);
        return false;
      }
    }
    std::optional<CarriedInstances> c = carrier.Carry(f->index, f->images.gray);
    if (!c) return true;  // the segmentation thread stopped before publishing anything
    UseCarried(std::move(*c), f);
    return true;
  };
  BoundedQueue<LoadedFrame>& extraction_input = async ? camera : loaded;
  stages.Start(
      "extraction",
      [&] {
        while (std::optional<LoadedFrame> f = extraction_input.Pop()) {
          if (StopRequested(options)) break;
          // The mask-free part of the extraction in a helper thread while the masks are carried
          // (RunOptions::parallel_extraction); it only reads the image, which outlives it.
          std::future<PreparedExtraction> prepared;
          if (async && options.parallel_extraction && f->unreadable.empty()) {
            prepared = std::async(std::launch::async, [&slam, &gray = f->images.gray] {
              const auto t0 = std::chrono::steady_clock::now();
              PreparedExtraction p{slam.PrepareExtraction(gray), 0.0};
              p.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                         .count();
              return p;
            });
          }
          if (async && f->unreadable.empty() && !carry_masks(&*f)) {
            if (prepared.valid()) prepared.wait();
            continue;
          }
          Extracted e;
          if (!f->unreadable.empty()) {
            e.report = SkippedReport(dataset, *f);
          } else {
            std::optional<PreparedExtraction> p;
            if (prepared.valid()) p = prepared.get();
            e.frame = Extract(slam, dataset, *f, &e.report, p ? &p->pyramid : nullptr);
            // The helper's part (alongside the carrying) counts as extraction time too.
            if (p) e.report.timings.extraction_ms += p->ms;
            e.instances = std::move(f->instances);
            e.segmented = f->segmented;
            e.depth_m = f->images.depth_m;
            if (observer) e.bgr = f->images.bgr;
          }
          e.arrival = f->arrival;
          if (!extracted.Push(std::move(e))) break;
        }
      },
      [&] {
        extracted.Close();
        to_segment.Close();
      });
  if (options.mapping_thread) {
    stages.Start(
        "local mapping",
        [&] {
          if (options.realtime) LowerThisThreadPriority(mapping_nice);
          while (std::optional<KeyFrameId> kf = keyframes.Pop()) {
            if (StopRequested(options)) break;  // the keyframe stays in the map, not locally mapped
            FrameReport unused;
            slam.MapKeyFrame(*kf, &unused);
            if (slam_options.loop_thread && !to_close.Push(*kf)) break;  // loop closing failed
          }
        },
        [&] { to_close.Close(); });
  }
  if (slam_options.loop_thread) {
    stages.Start(
        "loop closing",
        [&] {
          if (options.realtime) LowerThisThreadPriority(mapping_nice);
          while (std::optional<KeyFrameId> kf = to_close.Pop()) {
            if (StopRequested(options)) break;
            FrameReport unused;
            slam.CloseLoops(*kf, &unused);
          }
        },
        [&] { to_close.Close(); });
  }
  // When the last processed frame got its pose (the processed frame rate's end, not the threads'
  // ends: the mapping and segmentation threads finish their current work after it).
  std::optional<std::chrono::steady_clock::time_point> last_pose;
  stages.RunHere(
      "tracking",
      [&] {
        while (std::optional<Extracted> e = extracted.Pop()) {
          if (StopRequested(options)) break;
          if (!e->report.skipped.empty()) {
            recorder.AddSkipped(e->report);
            Observe(observer, slam, e->report);
            continue;
          }
          Frame tracked;
          const KeyFrameId kf =
              slam.TrackFrame(std::move(e->frame), &e->report, observer ? &tracked : nullptr);
          if (options.realtime) {
            last_pose = std::chrono::steady_clock::now();
            e->report.latency_ms =
                std::chrono::duration<double, std::milli>(*last_pose - e->arrival).count();
          }
          recorder.AddFrameMasks(options, e->report.index, kf != kNoKeyFrame, e->instances,
                                 e->depth_m);
          if (kf != kNoKeyFrame) {
            if (!options.mapping_thread) {
              slam.MapKeyFrame(kf, &e->report);
            } else if (!keyframes.Push(kf)) {
              break;  // the mapping stage failed
            }
          }
          recorder.Add(e->report);
          Observe(observer, slam, e->report, &e->bgr, e->segmented ? &e->instances : nullptr,
                  &tracked);
        }
      },
      [&] { keyframes.Close(); });
  stages.Join();
  if (options.realtime) {
    const auto end = last_pose.value_or(std::chrono::steady_clock::now());
    dropped.insert(dropped.end(), not_processed.begin(), not_processed.end());
    std::sort(dropped.begin(), dropped.end());
    recorder.SetCamera(offered, std::move(dropped),
                       std::chrono::duration<double>(end - camera_start).count());
  }
  if (async) recorder.SetAsyncSegmentation(detection_ms, headroom_wait_ms);
  return Finish(recorder, dataset, settings, options, slam, start, segmenter);
}

RunSummary Run(const RgbdSource& dataset, const Settings& settings, const RunOptions& options,
               const ProgressFn& progress, Segmenter* segmenter) {
  if (options.realtime && !options.threaded)
    throw InputError("the camera-rate mode needs the threaded pipeline (RunOptions::threaded)");
  return options.threaded ? RunThreaded(dataset, settings, options, progress, segmenter)
                          : RunSequential(dataset, settings, options, progress, segmenter);
}

}  // namespace detslam
