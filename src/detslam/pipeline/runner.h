// Runs the SLAM system over a whole RGB-D dataset and writes the outputs:
// trajectory.txt (TUM format, every tracked frame), keyframes.txt, map.ply (landmarks) and
// run.json (settings, timings, counts). All outputs are written atomically at the end, also when
// the run is stopped early (RunOptions::stop).
#pragma once

#include <atomic>
#include <functional>
#include <string>
#include <vector>

#include "detslam/core/stats.h"
#include "detslam/dense/dense_fusion.h"
#include "detslam/io/dataset.h"
#include "detslam/io/settings.h"
#include "detslam/pipeline/run_observer.h"
#include "detslam/pipeline/slam_system.h"
#include "detslam/segmentation/segmenter.h"

namespace detslam {

struct RunOptions {
  std::string out_dir = "out";  // where outputs go (created)
  int64_t max_frames = -1;      // stop after this many frames (< 0: all)
  bool threaded = false;        // one thread per stage (see RunThreaded)
  bool mapping_thread = false;  // threaded: local mapping in its own thread (not deterministic)
  // With mapping_thread: loop closing in a thread of its own too (SlamOptions::loop_thread);
  // false: the local-mapping thread closes loops after each keyframe.
  bool loop_thread = true;
  size_t queue_capacity = 4;    // frames buffered between the threaded stages
  // Camera-rate mode (threaded only; RunThreaded): a camera thread offers frame i when its
  // timestamp comes (relative to the first frame's), as a live camera delivers them, and holds one
  // frame: a frame the pipeline has not taken when the next arrives is dropped, never queued
  // (RunSummary::dropped_frames). The queues between the stages then hold one frame each, and each
  // processed frame's latency from its arrival to its pose goes into FrameReport::latency_ms.
  bool realtime = false;
  // Camera-rate mode with a segmenter: asynchronous segmentation. The segmentation thread takes
  // the newest frame whenever it is free and publishes its instances; no other stage waits for it:
  // each frame uses the newest instances carried to it by the mask propagation (MaskCarrier), with
  // their age in FrameReport::mask_age, and a frame whose masks are older than
  // slam.dynamic.keyframe_max_mask_age makes no keyframe. false: every processed frame is
  // segmented before extraction.
  bool async_segmentation = true;
  // Asynchronous segmentation, the start: the map's first points need masks, so the first frame
  // waits for its own. true: it is then processed, and the frames that arrived before its masks
  // are dropped instead of queueing behind it; false: the first frame is not processed either,
  // and tracking starts with the next frame, its masks carried from the first. Chosen on the
  // tuning seeds (README, Options).
  bool first_frame_waits_for_masks = true;
  // Asynchronous segmentation: the part of a frame's feature extraction that needs no masks (image
  // pyramid, blurred levels, strong FAST corners; SlamSystem::PrepareExtraction) runs in a helper
  // thread while the frame's masks are carried to it, so that a frame's pose comes sooner. The
  // keypoints are the same either way.
  bool parallel_extraction = true;
  // Sequential mode with a segmenter: the asynchronous segmentation above, simulated so that it is
  // deterministic: the detector takes this many input frames for each frame it segments (it starts
  // on the newest frame whenever it is free, and its masks are published before the frame that
  // many later is tracked; the first frame waits for its own), each frame uses the newest masks
  // carried to it, with their age, and the camera-rate keyframe rules apply. Frames are not
  // dropped and nothing runs at camera rate: it reproduces the masks' timing, not the frame
  // rate. 0: off (every frame segmented before its extraction). For choosing the camera-rate
  // settings by runs that repeat; a live run's detector time varies (docs/STATUS.md).
  int simulated_detector_frames = 0;
  // Asynchronous segmentation (camera rate or simulated_detector_frames): the geometric check's
  // mover regions are carried this many frames (MoverCheckOptions::region_frames, replacing
  // slam.dynamic.geometric's), because a person entering the view is in the masks only several
  // frames later. Chosen on the walking presets' tuning seeds 1-3 (README, Options).
  int camera_rate_region_frames = 10;
  // Camera-rate mode: the first frames, up to this many MiB of decoded images, are read and
  // decoded before the camera starts (a camera delivers decoded images; decoding PNG files would
  // take CPU time a live camera does not); later frames are read on time by the camera thread.
  size_t camera_preload_mb = 2048;
  // Camera-rate mode: the asynchronous segmentation thread and the local-mapping thread (and the
  // global bundle adjustment it starts) run at this nice value (Linux; 0 = the frame path's), so
  // that when the cores are busy the frames' path (camera, extraction, tracking) gets them first.
  // 5 was chosen on walking_xyz tuning seeds 1-3 (docs/BENCHMARKS.md, section realtime); key
  // Segmentation.CameraRateNice.
  int background_nice = 5;
  // Camera-rate mode: the nice value of the local-mapping and loop-closing threads (and the global
  // bundle adjustment they start); -1: background_nice. They hold the map's lock in short steps,
  // and a step of a thread the scheduler puts behind the frames' path holds tracking up longer.
  int mapping_nice = -1;
  // Camera-rate mode: the asynchronous segmentation thread under SCHED_IDLE
  // (MakeThisThreadIdlePriority) instead of background_nice.
  bool idle_segmentation = false;
  // Camera-rate mode: before each frame it takes, the asynchronous segmentation thread waits (up
  // to camera_rate_headroom_max_wait_ms) while the machine's cores were busy more than this share
  // of the last 100 ms (Linux /proc/stat, all processes; >= 1: never waits). With every core kept
  // busy, a virtual machine's host may stop a core for a whole period (about 100 ms on this
  // project's machines), and a frame in the frames' path then waits for it (docs/STATUS.md).
  // 0.95 (with 100 ms windows of 10 ms ticks on 2 cores: at least one idle tick) was chosen on
  // the walking presets' tuning seeds (README, Options).
  double camera_rate_max_busy = 0.95;
  double camera_rate_headroom_max_wait_ms = 100;
  // Camera-rate mode: OpenCV's threads during the run (cv::setNumThreads, process-wide; restored
  // after it); 0 keeps OpenCV's default (one per core). Mostly the detector's network uses them:
  // with 1 it runs in the segmentation thread alone, at that thread's lower priority, instead of
  // also on a worker thread that competes with the frames' path. 1 was chosen on the tuning seeds
  // 1-3 of the four walking presets (README, Options).
  int camera_rate_opencv_threads = 1;
  std::string save_map;         // write the final map to this map file (empty: none)
  std::string load_map;         // start from the map in this map file (empty: a new map)
  // The dense static map (dense/dense_fusion.h): after the run, the main map's keyframes are fused
  // at their final poses, without the pixels the Det-SLAM stage removed, and written here (PLY;
  // empty: none). dense_progress (may be empty) is told each keyframe fused.
  std::string dense_map;
  TsdfOptions dense;
  DenseProgressFn dense_progress;
  // With a segmenter: write each keyframe's removed pixels to out_dir/keyframe_masks/NNNNNN.png
  // (the main map's keyframes; `detslam densify` reads them).
  bool keyframe_masks = true;
  // When *stop becomes true (e.g. set by a signal handler): the frame in progress is finished,
  // frames still queued are dropped, a running global BA stops after its current iteration, and
  // the outputs of the frames processed so far are written (RunSummary::interrupted).
  const std::atomic<bool>* stop = nullptr;
  // Told about every frame (e.g. the live viewer; may be null). In sequential mode it may hold the
  // run before each frame (pause, step).
  RunObserver* observer = nullptr;
  SlamOptions slam;
};

// SlamOptions from settings (ORBextractor.*, Camera.fps and detslam's own keys, see
// settings_keys.h; throws InputError for a bad or unknown key), with `seed` for RANSAC.
SlamOptions SlamOptionsFromSettings(const Settings& settings, uint64_t seed);

struct RunSummary {
  size_t frames = 0;  // processed (fewer than the dataset's when interrupted or max_frames)
  size_t tracked = 0;
  bool interrupted = false;  // stopped early by RunOptions::stop
  size_t skipped = 0;        // frames whose images could not be read (FrameReport::skipped)
  size_t keyframes = 0;
  size_t landmarks = 0;
  size_t relocalizations = 0;
  size_t loops = 0;  // loops closed
  // Several maps: maps started (the first included), merges, maps left at the end, and frames with
  // a pose in the main map (trajectory.txt; the others go to trajectory_map<N>.txt).
  int maps_started = 0, maps_merged = 0, maps_left = 0;
  size_t tracked_main = 0;
  LoopDetectionStats loop_detection;
  int global_ba_runs = 0;     // global bundle adjustments started after loops
  int global_ba_stopped = 0;  // ... stopped early by a newer loop (solution discarded)
  std::vector<int64_t> global_ba_applied_after_frames;  // SlamSystem's
  uint64_t map_file_bytes = 0;  // size of the map file written (save_map)
  uint64_t loaded_keyframes = 0, loaded_landmarks = 0;  // of the map loaded (load_map)
  double map_load_ms = 0;                               // reading and restoring it
  std::vector<LoopRecord> loop_records;
  // Camera-rate mode (RunOptions::realtime): frames the camera offered, the indices of those
  // dropped because the pipeline was busy (with asynchronous segmentation also those at the start,
  // RunOptions::first_frame_waits_for_masks), and the latency from a frame's arrival to its pose over
  // the frames processed (ms; also its 99th percentile).
  size_t offered = 0;
  std::vector<int64_t> dropped_frames;
  double camera_s = 0;  // from the camera's start (after preloading) to the last frame's pose
  double ProcessedFps() const { return camera_s > 0 ? frames / camera_s : 0.0; }
  ErrorStats latency;
  double latency_p99_ms = 0;
  // Asynchronous segmentation (RunOptions::async_segmentation): frames the segmentation thread
  // segmented, the age of the masks each processed frame used (input frames), and the keyframes
  // the tracker asked for that were not made because the masks were too old.
  bool async_segmentation = false;
  size_t frames_segmented = 0;
  // RunOptions::camera_rate_max_busy: the segmentation thread's waits for idle cores (ms, summed).
  double headroom_wait_ms = 0;
  ErrorStats mask_age;
  size_t keyframes_deferred = 0;
  size_t keyframes_stale_masks = 0;  // made with stale masks after waiting (FrameReport)
  // DetSlamOptions::keyframe_clean_own_masks: keyframes cleaned by their own masks, and the
  // keypoints that relabelled.
  size_t keyframes_cleaned = 0, keypoints_cleaned = 0;
  int keyframes_mapped_in_burst = 0;  // SlamSystem::keyframes_mapped_in_burst
  size_t keyframe_masks = 0;  // written to out_dir/keyframe_masks
  DenseMapStats dense;        // of the dense map (dense_map)
  double wall_s = 0;
  ErrorStats segmentation, extraction, tracking, mapping, total;  // per-stage times, ms
  ErrorStats loop_closing;  // per keyframe, ms (SlamSystem::loop_closing_times_ms)
  bool loop_thread = false;  // loop closing ran in a thread of its own
  std::string segmenter;  // backend name, empty without segmentation
  std::vector<FrameReport> reports;
  double TrackedFraction() const { return frames ? static_cast<double>(tracked) / frames : 0.0; }
};

using ProgressFn = std::function<void(size_t done, size_t total, const FrameReport& last)>;

// Sequential mode: one frame at a time through extraction, tracking and local mapping.
// Deterministic for a given dataset, settings and seed.
// In every mode a frame whose images cannot be read (RgbdSource::Load throws InputError: corrupt
// or missing file, wrong type or size) is skipped with a warning and listed in run.json
// (skipped_frames); the run goes on. When no frame at all can be read the run throws InputError
// with the first frame's reason and writes nothing.
RunSummary RunSequential(const RgbdSource& dataset, const Settings& settings,
                         const RunOptions& options, const ProgressFn& progress = nullptr,
                         Segmenter* segmenter = nullptr);

// Threaded mode: a loader/segmentation thread feeds an extraction thread, which feeds the
// tracking thread (the calling one), through bounded queues (closing a queue ends the stream);
// with options.realtime a camera thread loads the frames and offers them at their timestamps to
// the segmentation thread, dropping those it cannot take; with options.async_segmentation too, the
// camera feeds the extraction thread, which hands the newest frame to a segmentation thread that
// nothing waits for (see RunOptions::async_segmentation).
// With options.mapping_thread, local mapping runs in a fourth thread fed by a keyframe queue
// (results then depend on timing), and with options.loop_thread loop closing in a fifth, fed by
// the keyframes local mapping finished; without mapping_thread, mapping and loop closing run in
// the tracking thread and the trajectory equals the sequential one. An exception in any stage
// stops the others and is rethrown here.
RunSummary RunThreaded(const RgbdSource& dataset, const Settings& settings,
                       const RunOptions& options, const ProgressFn& progress = nullptr,
                       Segmenter* segmenter = nullptr);

// RunThreaded if options.threaded, else RunSequential.
// With a segmenter, the Det-SLAM stage (options.slam.dynamic) segments every
// `segment_every`-th frame (masks follow the optical flow in between) and rejects keypoints on
// dynamic objects; in threaded mode segmentation runs in the loading thread.
RunSummary Run(const RgbdSource& dataset, const Settings& settings, const RunOptions& options,
               const ProgressFn& progress = nullptr, Segmenter* segmenter = nullptr);

}  // namespace detslam
