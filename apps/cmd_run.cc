// detslam run: SLAM over a TUM/Bonn-layout RGB-D folder or a ROS 1 bag (sequential by default;
// --threaded runs one thread per stage).
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>

#include "commands.h"
#include "dense_args.h"
#include "source_args.h"
#include "stop_signals.h"
#include "detslam/core/check.h"
#include "detslam/io/dataset.h"
#include "detslam/io/rosbag_source.h"
#include "detslam/io/settings.h"
#include "detslam/pipeline/runner.h"
#include "detslam/pipeline/settings_keys.h"
#include "detslam/segmentation/dnn_segmenter.h"
#include "detslam/segmentation/segmenter_factory.h"
#include "detslam/viewer/live_viewer.h"
#include "detslam/viewer/viewer_server.h"

namespace detslam::app {
namespace {

struct RunArgs {
  SourceArgs from;  // --dataset or --rosbag, --config
  std::string out = "out";
  uint64_t seed = 42;
  int64_t max_frames = -1;
  bool no_progress = false;
  std::string save_map;
  std::string load_map;
  bool localization = false;
  bool threaded = false;
  bool realtime = false;  // --realtime: frames offered at their timestamps (implies threaded)
  bool sync_segmentation = false;  // --sync-segmentation: with --realtime, segment every frame taken
  int camera_preload_mb = -1;      // --camera-preload-mb (-1: RunOptions' default)
  int simulate_detector_frames = 0;  // --simulate-camera-rate-masks N
  bool inline_mapping = false;
  bool inline_loop_closing = false;
  std::string segmenter;  // empty: dnn if the models are found, else none
  std::string models;
  double alpha = -1;
  bool no_depth_step = false;
  bool geometric_check = false;
  bool no_geometric_check = false;
  int segment_every = 0;  // 0: from the settings (Segmentation.EveryK, default 1)
  std::string vocabulary;  // empty: from the settings (Place.Vocabulary, default the shipped one)
  std::vector<std::string> overrides;  // --set KEY=VALUE
  std::string dense_map;               // --dense-map FILE.ply
  TsdfOptions dense;
  int viewer_port = -1;  // --viewer [PORT] (0: a free port; < 0: no viewer)
  bool viewer_keep = false;
  bool paused = false;
};

constexpr char kRunStopMessage[] =
    "\ndetslam: stopping after the current frame and writing the outputs so far (again to quit "
    "at once)\n";

// The live viewer of a run (--viewer): its content and its web server.
struct Viewer {
  std::unique_ptr<LiveViewer> content;
  std::unique_ptr<ViewerServer> server;
};

Viewer StartViewer(const RunArgs& a, const RgbdSource& dataset, const std::string& segmenter) {
  Viewer v;
  if (a.viewer_port < 0) return v;
  if (a.threaded && a.paused) throw InputError("--paused needs a sequential run (no --threaded)");
  LiveViewerOptions vo;
  vo.title = dataset.name() + " (segmenter " + segmenter + ", " +
             (a.realtime ? "camera rate" : a.threaded ? "threaded" : "sequential") + ")";
  if (!dataset.groundtruth_path().empty()) {
    try {
      vo.ground_truth = ReadTumTrajectory(dataset.groundtruth_path());
    } catch (const InputError& e) {
      std::fprintf(stderr, "note: viewer without ground truth: %s\n", e.what());
    }
  }
  vo.start_paused = a.paused;
  vo.stop = &StopFlag();
  v.content = std::make_unique<LiveViewer>(std::move(vo));
  ViewerServerOptions so;
  so.port = a.viewer_port;
  v.server = std::make_unique<ViewerServer>(v.content.get(), so);
  std::printf("viewer: %s (open it in a browser%s)\n", v.server->url().c_str(),
              a.paused ? "; paused: press Step or Resume" : "");
  std::fflush(stdout);
  return v;
}

// A one-line progress bar on stderr when it is a terminal; otherwise a log line every 100 frames.
class ProgressBar {
 public:
  explicit ProgressBar(bool enabled) : tty_(enabled && isatty(fileno(stderr))) {}
  void Update(size_t done, size_t total, const FrameReport& r) {
    if (!tty_) {
      if (done % 100 == 0 || done == total)
        std::fprintf(stderr, "[run] %zu/%zu frames, %d keyframes, %d map points\n", done, total,
                     r.map_keyframes, r.map_points);
      return;
    }
    const int width = 30;
    const int filled = static_cast<int>(width * done / std::max<size_t>(total, 1));
    std::fprintf(stderr, "\r[%.*s%*s] %zu/%zu  %-14s inliers %4d  %5.1f ms", filled,
                 "##############################", width - filled, "", done, total,
                 ToString(r.tracking.state), r.tracking.num_inliers,
                 r.timings.extraction_ms + r.timings.tracking_ms + r.timings.mapping_ms);
    if (done == total) std::fprintf(stderr, "\n");
    std::fflush(stderr);
  }

 private:
  bool tty_;
};

void Run(RunArgs a) {
  namespace fs = std::filesystem;
  if (a.realtime) a.threaded = true;
  OpenedSource opened = OpenSource(a.from);
  const std::unique_ptr<RgbdSource> source = std::move(opened.source);
  Settings settings = std::move(opened.settings);
  const bool bag_has_tf = opened.bag_has_tf;
  const RgbdSource& dataset = *source;
  ApplySettingOverrides(a.overrides, &settings);
  const ResolvedSettings resolved = ResolveSettings(settings);  // rejects bad or unknown keys
  RunOptions options = resolved.run;  // the run's own keys (e.g. Segmentation.CameraRate*)
  options.out_dir = a.out;
  options.max_frames = a.max_frames;
  options.save_map = a.save_map;
  options.load_map = a.load_map;
  options.dense_map = a.dense_map;
  options.dense = a.dense;
  options.threaded = a.threaded;
  options.realtime = a.realtime;
  options.async_segmentation = !a.sync_segmentation;
  if (a.simulate_detector_frames > 0 && a.threaded)
    throw InputError("--simulate-camera-rate-masks needs a sequential run (no --threaded or --realtime)");
  options.simulated_detector_frames = a.simulate_detector_frames;
  if (a.camera_preload_mb >= 0) options.camera_preload_mb = static_cast<size_t>(a.camera_preload_mb);
  options.slam = SlamOptionsFromSettings(settings, a.seed);
  options.mapping_thread = a.threaded && !a.inline_mapping;
  options.loop_thread = !a.inline_loop_closing;
  if (a.alpha >= 0) options.slam.dynamic.filter.alpha = a.alpha;
  if (a.no_depth_step) options.slam.dynamic.filter.depth_step = false;
  if (a.geometric_check) options.slam.dynamic.geometric.enabled = true;
  if (a.no_geometric_check) options.slam.dynamic.geometric.enabled = false;
  if (a.segment_every > 0) options.slam.dynamic.segment_every = a.segment_every;
  if (!a.vocabulary.empty()) options.slam.vocabulary = a.vocabulary;
  if (a.localization && a.load_map.empty())
    throw InputError("--localization needs a map to localise in (--load-map FILE)");
  options.slam.localization = a.localization;
  std::string error;
  if (!options.slam.Check(&error)) throw InputError(settings.source, 0, error);
  const std::string models_dir = a.models.empty() ? DefaultModelsDir() : a.models;
  std::string spec = a.segmenter;
  // At camera rate the detector runs at its own input size (Segmentation.CameraRateInputSize).
  const bool camera_rate_masks = a.realtime || a.simulate_detector_frames > 0;
  const SegmenterSettings segmenter_settings =
      camera_rate_masks ? ForCameraRate(resolved.segmenter) : resolved.segmenter;
  std::unique_ptr<Segmenter> segmenter;
  if (spec.empty()) {
    try {
      segmenter = MakeSegmenter("dnn", dataset.name(), segmenter_settings, models_dir);
      spec = "dnn";
    } catch (const InputError& e) {
      std::fprintf(stderr, "note: no dynamic-object segmentation (pass --segmenter dnn|masks:DIR|gt|none): %s\n", e.what());
      spec = "none";
    }
  } else {
    segmenter = MakeSegmenter(spec, dataset.name(), segmenter_settings, models_dir);
  }
  std::printf("detslam run (%s, segmenter %s): %zu frames from %s (settings: %s)\n",
              a.realtime ? "camera rate" : a.threaded ? "threaded" : "sequential", spec.c_str(), dataset.size(), dataset.name().c_str(),
              settings.source.c_str());
  if (a.paused && a.viewer_port < 0) throw InputError("--paused needs --viewer");
  const Viewer viewer = StartViewer(a, dataset, spec);
  options.observer = viewer.content.get();
  ProgressBar bar(!a.no_progress);
  options.stop = &StopFlag();
  options.dense_progress = [&](size_t done, size_t total) { DenseProgress(done, total, !a.no_progress); };
  RunSummary s;
  {
    const StopSignals signals(kRunStopMessage);
    s = Run(dataset, settings, options, [&](size_t d, size_t t, const FrameReport& r) { bar.Update(d, t, r); }, segmenter.get());
  }
  if (s.skipped > 0) std::printf("skipped %zu frames whose images could not be read (run.json skipped_frames)\n", s.skipped);
  if (s.interrupted) std::printf("interrupted after %zu of %zu frames (signal %d): outputs of those frames written\n", s.frames, dataset.size(), StopSignal());
  std::printf("tracked %zu/%zu frames (%.1f%%), %zu keyframes, %zu map points, %zu relocalisations, %zu loops closed\n",
              s.tracked, s.frames, 100.0 * s.TrackedFraction(), s.keyframes, s.landmarks, s.relocalizations, s.loops);
  if (s.maps_started > 1 || s.maps_left > 1) {
    std::printf("maps: %d started (tracking lost, relocalisation failed), %d merged, %d left; trajectory.txt holds %zu frames%s\n",
                s.maps_started, s.maps_merged, s.maps_left, s.tracked_main,
                s.maps_left > 1 ? " (the other maps: trajectory_map<N>.txt, each in its own frame)" : "");
  }
  if (a.realtime) {
    std::printf("camera rate: %zu frames offered, %zu dropped (%.1f%%) because the pipeline was busy, %.1f frames/s processed; "
                "latency from arrival to pose: median %.1f ms, 99th percentile %.1f ms\n",
                s.offered, s.dropped_frames.size(), s.offered ? 100.0 * s.dropped_frames.size() / s.offered : 0.0,
                s.ProcessedFps(), s.latency.median, s.latency_p99_ms);
    if (s.async_segmentation) {
      std::printf("asynchronous segmentation: %zu frames segmented; masks used %.1f frames old (median, max %.0f); "
                  "%zu keyframes deferred for masks older than %d frames, %zu made with such masks (tracking too weak to wait, or waited %d frames)\n",
                  s.frames_segmented, s.mask_age.median, s.mask_age.max, s.keyframes_deferred,
                  options.slam.dynamic.keyframe_max_mask_age, s.keyframes_stale_masks,
                  options.slam.dynamic.keyframe_max_wait);
    }
  }
  if (options.simulated_detector_frames > 0 && s.async_segmentation) {
    std::printf("simulated camera-rate masks (the detector takes %d frames): %zu frames segmented; masks used %.1f frames old (median, max %.0f); "
                "%zu keyframes deferred for masks older than %d frames, %zu made with such masks\n",
                options.simulated_detector_frames, s.frames_segmented, s.mask_age.median, s.mask_age.max,
                s.keyframes_deferred, options.slam.dynamic.keyframe_max_mask_age, s.keyframes_stale_masks);
  }
  if (!s.segmenter.empty()) std::printf("segmentation (%s): median %.1f ms per frame\n", s.segmenter.c_str(), s.segmentation.median);
  std::printf("median ms per frame: extraction %.1f, tracking %.1f, total %.1f; local mapping %.1f per keyframe\n",
              s.extraction.median, s.tracking.median, s.total.median, s.mapping.median);
  const fs::path out(a.out);
  std::printf("outputs: %s %s %s %s\n", (out / "trajectory.txt").c_str(), (out / "keyframes.txt").c_str(),
              (out / "map.ply").c_str(), (out / "run.json").c_str());
  if (!a.save_map.empty()) std::printf("map file: %s (%.1f MB)\n", a.save_map.c_str(), s.map_file_bytes / 1e6);
  if (!a.dense_map.empty()) PrintDenseSummary(a.dense_map, s.dense, s.keyframe_masks, !s.segmenter.empty());
  if (!dataset.groundtruth_path().empty()) {
    std::printf("evaluate: detslam eval --gt %s --est %s --frames %s\n", dataset.groundtruth_path().c_str(),
                (out / "trajectory.txt").c_str(), dataset.name().c_str());
  }
  if (bag_has_tf) {
    std::printf("ground truth (if the bag's tf holds it): detslam rosbag groundtruth %s --out %s, then detslam eval --gt %s --est %s\n",
                a.from.rosbag.c_str(), (out / "groundtruth.txt").c_str(), (out / "groundtruth.txt").c_str(),
                (out / "trajectory.txt").c_str());
  }
  if (viewer.content) {
    const LiveViewer::Cost c = viewer.content->cost();
    std::printf("viewer cost: %.3f ms per frame in the tracking thread (max %.1f), %llu map snapshots of %.2f ms (max %.1f)\n",
                c.on_frame_ms_mean, c.on_frame_ms_max, static_cast<unsigned long long>(c.map_snapshots),
                c.map_snapshot_ms_mean, c.map_snapshot_ms_max);
  }
  if (viewer.server && a.viewer_keep && !s.interrupted) {
    std::printf("viewer: the run has finished; still at %s (Ctrl-C to quit)\n", viewer.server->url().c_str());
    std::fflush(stdout);
    const StopSignals signals("\ndetslam: viewer closed\n");
    signals.Wait();
  }
  if (s.interrupted) {
    std::fflush(stdout);
    throw CommandFailed("run interrupted (outputs written for the frames processed)", 128 + StopSignal());
  }
}

}  // namespace

void AddRunCommand(CLI::App& app) {
  auto args = std::make_shared<RunArgs>();
  auto* cmd = app.add_subcommand("run", "Run RGB-D SLAM on a TUM/Bonn-layout folder or a ROS 1 bag");
  AddSourceOptions(cmd, &args->from);
  cmd->add_option("--out", args->out, "Output folder")->capture_default_str();
  cmd->add_option("--seed", args->seed, "Seed for RANSAC (runs are deterministic per seed)")->capture_default_str();
  cmd->add_option("--max-frames", args->max_frames, "Stop after N frames");
  cmd->add_option("--segmenter", args->segmenter,
                  "Dynamic objects: dnn (detector + person masks), masks:DIR (precomputed), gt (synthetic ground truth), none; default dnn when its models are found");
  cmd->add_option("--models", args->models, "Models folder for --segmenter dnn (default $DETSLAM_MODELS or ../shared/models)");
  cmd->add_option("--alpha", args->alpha, "Det-SLAM depth-step widening factor alpha (default from settings Dynamic.Alpha, else 0.1)");
  cmd->add_flag("--no-depth-step", args->no_depth_step, "Mask step only (no depth-ROI step)");
  auto* geo = cmd->add_flag("--geometric-check", args->geometric_check,
                            "Also reject movers the segmenter missed by their residual against the tracked pose (settings Dynamic.GeometricCheck, default on)");
  cmd->add_flag("--no-geometric-check", args->no_geometric_check, "Turn the geometric check off")->excludes(geo);
  cmd->add_option("--vocabulary", args->vocabulary,
                  "Bag-of-words vocabulary for relocalisation and loop detection, or none (settings Place.Vocabulary; default the shipped data/vocabulary/orb_k10_l5.dslvoc or $DETSLAM_VOCABULARY)");
  cmd->add_option("--segment-every", args->segment_every,
                  "Run the segmenter on every K-th frame only; masks follow the optical flow in between (settings Segmentation.EveryK, default 1)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--set", args->overrides,
                  "Override a settings key, KEY=VALUE (repeatable), e.g. --set Dynamic.MaskDilation=10; "
                  "the keys: detslam settings --list");
  cmd->add_flag("--threaded", args->threaded,
                "One thread per stage: loading+segmentation, extraction, tracking, local mapping, loop closing (real-time use; not bit-reproducible)");
  cmd->add_flag("--realtime", args->realtime,
                "Camera rate: offer the frames at their timestamps as a live camera would (implies --threaded); a frame the pipeline has not taken when the next arrives is dropped, never queued; run.json reports the frames dropped and each frame's latency from arrival to pose");
  cmd->add_flag("--sync-segmentation", args->sync_segmentation,
                "With --realtime: segment each frame taken before extracting it (the pipeline waits for the detector); default: asynchronous segmentation, each frame uses the newest masks carried to it by optical flow");
  cmd->add_option("--simulate-camera-rate-masks", args->simulate_detector_frames,
                  "Sequential run with the masks of --realtime's asynchronous segmentation, deterministically: the camera-rate detector takes N input frames per frame it segments, each frame uses the newest masks carried to it, and the camera-rate keyframe rules apply (reproduces the masks' timing, not the frame rate)")
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--camera-preload-mb", args->camera_preload_mb,
                  "With --realtime: decode the first frames, up to this many MiB, before the camera starts (a camera delivers decoded images); later frames are read and decoded on time by the camera thread (default 2048; 0: every frame on time)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--inline-mapping", args->inline_mapping,
                "With --threaded: local mapping in the tracking thread (then the trajectory equals the sequential one)");
  cmd->add_flag("--inline-loop-closing", args->inline_loop_closing,
                "With --threaded: loop closing in the local-mapping thread, after each keyframe's local mapping (default: a thread of its own)");
  cmd->add_flag("--no-progress", args->no_progress, "No progress bar");
  cmd->add_option("--save-map", args->save_map,
                  "Write the final map to this map file (keyframes, map points, covisibility; `detslam map info FILE`)");
  cmd->add_option("--load-map", args->load_map,
                  "Start from the map in this map file (written by --save-map with the same camera, ORB settings and vocabulary): relocalise in it, then extend it");
  cmd->add_flag("--localization", args->localization,
                "With --load-map: track against the loaded map only (no new keyframes or map points)");
  cmd->add_option("--dense-map", args->dense_map,
                  "After the run, fuse the keyframes at their final poses, without the dynamic objects' pixels, into a TSDF volume and write its surface here (PLY point cloud with colours and normals)");
  AddDenseOptions(cmd, &args->dense);
  cmd->add_option("--viewer", args->viewer_port,
                  "Serve a live view of the run on http://127.0.0.1:PORT/ (frame, keypoints, masks, 3-D map, counters; no PORT or 0: a free port, printed)")
      ->expected(0, 1)
      ->default_str("0")
      ->check(CLI::Range(0, 65535));
  cmd->add_flag("--viewer-keep", args->viewer_keep, "With --viewer: keep serving after the run until Ctrl-C");
  cmd->add_flag("--paused", args->paused, "With --viewer (sequential): start paused; the page's Step and Resume buttons run it");
  cmd->callback([args] { Run(*args); });
}

}  // namespace detslam::app
