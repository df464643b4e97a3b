// Whole-pipeline tests: SLAM on real TUM data (../shared) and on synthetic sequences with ground
// truth, asserting tracked fraction and accuracy, and determinism of sequential runs.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/core/utility.hpp>
#include <sstream>
#include <thread>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>

#include "detslam/core/check.h"
#include "detslam/eval/evaluate.h"
#include "detslam/eval/run_log.h"
#include "detslam/io/dataset.h"
#include "detslam/io/settings.h"
#include "detslam/map/map_file.h"
#include "detslam/pipeline/runner.h"
#include "detslam/pipeline/settings_keys.h"
#include "detslam/place/default_vocabulary.h"
#include "detslam/segmentation/mask_dir.h"
#include "detslam/segmentation/segmenter_factory.h"
#include "detslam/synth/writer.h"
#include "integration_util.h"
#include "support/cli_runner.h"
#include "support/shared_data.h"

namespace detslam {
namespace {

namespace fs = std::filesystem;

using integration::WriteStaticSequence;
using testing::TempDir;

struct SlamRun {
  RunSummary summary;
  EvalResult eval;
  std::string trajectory_path;
};

// Writes what the wrapped segmenter returns into a masks folder (as `detslam segment` does).
class RecordingSegmenter : public Segmenter {
 public:
  RecordingSegmenter(std::unique_ptr<Segmenter> inner, const std::string& dir)
      : inner_(std::move(inner)), writer_(dir) {}
  ~RecordingSegmenter() override { writer_.Finish(); }
  std::vector<Instance> Segment(const SegmenterInput& input) override {
    std::vector<Instance> found = inner_->Segment(input);
    writer_.Add(input.stamp, input.bgr.size(), found);
    return found;
  }
  void WarmUp(const SegmenterInput& input) override { inner_->WarmUp(input); }
  std::string name() const override { return inner_->name(); }

 private:
  std::unique_ptr<Segmenter> inner_;
  MaskDirWriter writer_;
};

// record_masks: a folder to write the segmenter's masks into (empty: none).
SlamRun RunAndEvaluate(const std::string& dataset_dir, const std::string& out_dir, uint64_t seed,
                       bool threaded = false, const std::string& segmenter_spec = "none",
                       bool mapping_thread = false, const std::string& models_dir = "",
                       const std::string& record_masks = "") {
  const RgbdDataset dataset = RgbdDataset::Open(dataset_dir, {});
  const Settings settings = PresetForDataset(dataset_dir);
  RunOptions options;
  options.out_dir = out_dir;
  options.threaded = threaded;
  options.slam = SlamOptionsFromSettings(settings, seed);
  options.mapping_thread = mapping_thread;
  std::unique_ptr<Segmenter> segmenter =
      MakeSegmenter(segmenter_spec, dataset_dir, ResolveSettings(settings).segmenter, models_dir);
  if (!record_masks.empty()) {
    segmenter = std::make_unique<RecordingSegmenter>(std::move(segmenter), record_masks);
  }
  SlamRun run;
  run.summary = Run(dataset, settings, options, nullptr, segmenter.get());
  segmenter.reset();  // a recorder writes its instance list
  run.trajectory_path = (fs::path(out_dir) / "trajectory.txt").string();
  run.eval = EvaluateFiles(dataset.groundtruth_path(), run.trajectory_path, dataset_dir, {});
  return run;
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(DataSlamFr2Desk, TracksEveryFrameWithinFiveMillimetres) {
  DETSLAM_REQUIRE_SHARED("data/tum/rgbd_dataset_freiburg2_desk_subset50");
  const SlamRun run = RunAndEvaluate(testing::SharedPath("data/tum/rgbd_dataset_freiburg2_desk_subset50"),
                                     TempDir("fr2"), 42);
  EXPECT_EQ(run.summary.frames, 50u);
  EXPECT_EQ(run.summary.tracked, 50u);
  EXPECT_DOUBLE_EQ(run.eval.coverage.fraction, 1.0);
  EXPECT_LE(run.eval.ate.error_m.rmse, 0.005) << "ATE RMSE " << run.eval.ate.error_m.rmse;
  for (const char* f : {"trajectory.txt", "keyframes.txt", "map.ply", "run.json"}) {
    EXPECT_TRUE(fs::exists(fs::path(run.trajectory_path).parent_path() / f)) << f;
  }
}

TEST(DataSlamFr2Desk, SeededSequentialRunsAreIdentical) {
  DETSLAM_REQUIRE_SHARED("data/tum/rgbd_dataset_freiburg2_desk_subset50");
  const std::string dir = testing::SharedPath("data/tum/rgbd_dataset_freiburg2_desk_subset50");
  const SlamRun a = RunAndEvaluate(dir, TempDir("det_a"), 7);
  const SlamRun b = RunAndEvaluate(dir, TempDir("det_b"), 7);
  const std::string ta = ReadFile(a.trajectory_path), tb = ReadFile(b.trajectory_path);
  ASSERT_FALSE(ta.empty());
  // The header names the output folder; compare the pose lines.
  EXPECT_EQ(ta.substr(ta.find("\n1311")), tb.substr(tb.find("\n1311")));
}

TEST(DataSlamFr2Desk, ThreadedRunnerGivesTheSequentialTrajectory) {
  DETSLAM_REQUIRE_SHARED("data/tum/rgbd_dataset_freiburg2_desk_subset50");
  const std::string dir = testing::SharedPath("data/tum/rgbd_dataset_freiburg2_desk_subset50");
  const SlamRun a = RunAndEvaluate(dir, TempDir("seq"), 5, false);
  const SlamRun b = RunAndEvaluate(dir, TempDir("thr"), 5, true);
  const std::string ta = ReadFile(a.trajectory_path), tb = ReadFile(b.trajectory_path);
  EXPECT_EQ(ta.substr(ta.find("\n1311")), tb.substr(tb.find("\n1311")));
  EXPECT_EQ(b.summary.frames, 50u);
}

// Local mapping in its own thread: results depend on timing, so only accuracy is asserted.
TEST(DataSlamFr2Desk, MappingThreadTracksEveryFrameAccurately) {
  DETSLAM_REQUIRE_SHARED("data/tum/rgbd_dataset_freiburg2_desk_subset50");
  const std::string dir = testing::SharedPath("data/tum/rgbd_dataset_freiburg2_desk_subset50");
  const SlamRun run = RunAndEvaluate(dir, TempDir("mapping_thread"), 5, true, "none", true);
  EXPECT_EQ(run.summary.tracked, 50u);
  EXPECT_LE(run.eval.ate.error_m.rmse, 0.01) << "ATE RMSE " << run.eval.ate.error_m.rmse;
  EXPECT_GE(run.summary.keyframes, 2u);
}

// A merge in the threaded pipeline (mapping thread): a welded merge moves the map in two steps,
// the seam's bundle adjustment solved between them while tracking goes on (frames tracked
// meanwhile, keyframes made meanwhile taken into the pose graph). The map started after the cover
// must still merge into the first, welded, with nearly every frame that is not black in
// trajectory.txt and the accuracy of a covered run (atlas_test.cc runs the same sequentially).
TEST(IntegrationAtlas, MappingThreadWeldsTheMergeWhileTrackingGoesOn) {
  SynthOptions so;
  so.preset = "roam";
  so.seed = 2;
  so.people = false;
  so.cover_start_s = 8.0;
  so.cover_seconds = 2.0;
  const std::string seq = TempDir("roam_cover");
  WriteSequence(so, seq);
  const SlamRun run = RunAndEvaluate(seq, TempDir("roam_cover_threaded"), 42, true, "none", true);
  EXPECT_GE(run.summary.maps_merged, 1);
  EXPECT_EQ(run.summary.maps_left, 1);
  int welded = 0;
  for (const LoopRecord& loop : run.summary.loop_records) welded += loop.merge ? loop.welded_keyframes : 0;
  EXPECT_GE(welded, 2);
  const size_t not_black = run.summary.frames - 60;
  EXPECT_GE(run.summary.tracked_main, static_cast<size_t>(0.95 * not_black));
  EXPECT_LE(run.eval.ate.error_m.rmse, 0.02) << "ATE RMSE " << run.eval.ate.error_m.rmse;
}

// People walking through the view: without the dynamic filter the trajectory is far off; with
// the ground-truth masks (oracle segmenter) it stays close to the accuracy of the static twin.
TEST(IntegrationSlamDynamic, GroundTruthMasksRemoveThePeople) {
  SynthOptions so;
  so.preset = "walking_xyz";
  so.seed = 2;
  so.frames = 200;
  const std::string seq = TempDir("walking");
  WriteSequence(so, seq);
  so.people = false;
  const std::string twin = TempDir("walking_twin");
  WriteSequence(so, twin);
  const SlamRun with_gt = RunAndEvaluate(seq, TempDir("walking_gt"), 42, false, "gt");
  const SlamRun without = RunAndEvaluate(seq, TempDir("walking_none"), 42, false, "none");
  const SlamRun static_twin = RunAndEvaluate(twin, TempDir("walking_twin_run"), 42);
  EXPECT_EQ(with_gt.summary.tracked, with_gt.summary.frames);
  const double gt_rmse = with_gt.eval.ate.error_m.rmse, twin_rmse = static_twin.eval.ate.error_m.rmse;
  const double none_rmse = without.eval.ate.error_m.rmse;
  EXPECT_LE(gt_rmse, std::max(2.0 * twin_rmse, 0.01)) << "gt " << gt_rmse << " twin " << twin_rmse;
  EXPECT_GE(none_rmse, 3.0 * gt_rmse) << "none " << none_rmse << " gt " << gt_rmse;
  int frames_with_people = 0;
  for (const FrameReport& r : with_gt.summary.reports) frames_with_people += r.dynamic_instances > 0 ? 1 : 0;
  EXPECT_GT(frames_with_people, 100) << "the filter saw people in too few frames";
}

// The same with the default dnn segmenter (YOLOX-nano + Yolo-Fastest + person masks from
// ../shared/models) on people textured with the real TUM cut-outs: every frame tracked, ATE at most
// 1.5x the static twin's, and without the filter clearly worse. Seed 4 is neither a tuning seed
// (1-3) nor an evaluation seed (101+) of the benchmarks.
// It failed until the lost-instance depth tracking (Dynamic.DepthTrackFrames): the detectors miss
// a person cut by the left image border (a torso without a head) for frames 114-121, longer than
// the 3 frames a lost instance was carried, and the pose drifted by up to 3.2 cm (1.69x the twin);
// with the person followed in depth it is 0.98x (replayed masks, 2026-12-04).
TEST(DataSlamDynamic, DnnSegmenterKeepsTheStaticTwinsAccuracy) {
  DETSLAM_REQUIRE_SHARED("data/people/person_1.png");
  DETSLAM_REQUIRE_SHARED("models/yolox_nano/yolox_nano.onnx");
  SynthOptions so;
  so.preset = "walking_xyz";
  so.seed = 4;
  so.frames = 300;
  so.people_dir = testing::SharedPath("data/people");
  const std::string seq = TempDir("walking_dnn");
  WriteSequence(so, seq);
  so.people = false;
  const std::string twin = TempDir("walking_dnn_twin");
  WriteSequence(so, twin);
  const std::string masks = TempDir("walking_dnn_masks");
  const SlamRun with_dnn = RunAndEvaluate(seq, TempDir("walking_dnn_run"), 42, false, "dnn", false,
                                          testing::SharedPath("models"), masks);
  // The benchmarks replay dnn masks written once per sequence (detslam segment, masks:DIR): the
  // replay must give the live run's trajectory byte for byte (overlapping masks kept whole).
  const SlamRun replayed = RunAndEvaluate(seq, TempDir("walking_dnn_replay"), 42, false, "masks:" + masks);
  EXPECT_EQ(ReadFile(replayed.trajectory_path), ReadFile(with_dnn.trajectory_path))
      << "replayed masks do not give the live dnn run's trajectory";
  const SlamRun without = RunAndEvaluate(seq, TempDir("walking_dnn_none"), 42, false, "none");
  const SlamRun static_twin = RunAndEvaluate(twin, TempDir("walking_dnn_twin_run"), 42);
  EXPECT_EQ(with_dnn.summary.tracked, with_dnn.summary.frames);
  const double dnn_rmse = with_dnn.eval.ate.error_m.rmse;
  const double twin_rmse = static_twin.eval.ate.error_m.rmse;
  const double none_rmse = without.eval.ate.error_m.rmse;
  EXPECT_LE(dnn_rmse, 1.5 * twin_rmse) << "dnn " << dnn_rmse << " twin " << twin_rmse;
  EXPECT_GE(none_rmse, 3.0 * dnn_rmse) << "none " << none_rmse << " dnn " << dnn_rmse;
  int frames_with_people = 0;
  for (const FrameReport& r : with_dnn.summary.reports) frames_with_people += r.dynamic_instances > 0;
  EXPECT_GT(frames_with_people, 150) << "the detector found people in too few frames";
  std::printf("dnn %.2f mm, static twin %.2f mm (ratio %.2f), no filter %.2f mm, people in %d of %d "
              "frames\n", 1000 * dnn_rmse, 1000 * twin_rmse, dnn_rmse / twin_rmse,
              1000 * none_rmse, frames_with_people, static_cast<int>(with_dnn.summary.frames));
}

// A segmenter that fails from frame `fail_at` on (as a model file that cannot be read would; "from
// on": at camera rate that frame itself may be dropped).
class FailingSegmenter : public Segmenter {
 public:
  explicit FailingSegmenter(int64_t fail_at) : fail_at_(fail_at) {}
  std::vector<Instance> Segment(const SegmenterInput& input) override {
    if (input.index >= fail_at_) throw InputError("model.onnx", 0, "segmenter failed on frame " + std::to_string(fail_at_));
    return {};
  }
  std::string name() const override { return "failing"; }

 private:
  int64_t fail_at_;
};

// A stage that throws in its own thread ends the run with its message (no std::terminate, no
// hang), in every mode, and leaves no trajectory behind.
TEST(IntegrationRunner, AFailingStageEndsTheRunWithItsMessage) {
  const std::string seq = WriteStaticSequence("failing_stage", 1, 40);
  const RgbdDataset dataset = RgbdDataset::Open(seq, {});
  const Settings settings = PresetForDataset(seq);
  struct Mode {
    bool threaded, mapping_thread, realtime, async;
  };
  for (const auto& [threaded, mapping_thread, realtime, async] :
       {Mode{false, false, false, false}, {true, false, false, false}, {true, true, false, false},
        {true, true, true, false}, {true, true, true, true}}) {
    RunOptions options;
    options.out_dir = TempDir("failing_stage_run");
    options.threaded = threaded;
    options.mapping_thread = mapping_thread;
    options.realtime = realtime;
    options.async_segmentation = async;
    options.slam = SlamOptionsFromSettings(settings, 42);
    FailingSegmenter segmenter(25);
    try {
      detslam::Run(dataset, settings, options, nullptr, &segmenter);
      ADD_FAILURE() << "no error (threaded " << threaded << ", mapping thread " << mapping_thread
                    << ", camera rate " << realtime << ", asynchronous segmentation " << async << ")";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("segmenter failed on frame 25"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(fs::path(options.out_dir) / "trajectory.txt"));
  }
}

// A segmenter that takes `ms` per frame.
class SlowSegmenter : public Segmenter {
 public:
  explicit SlowSegmenter(int ms) : ms_(ms) {}
  std::vector<Instance> Segment(const SegmenterInput&) override {
    opencv_threads_ = cv::getNumThreads();
    std::this_thread::sleep_for(std::chrono::milliseconds(ms_));
    return {};
  }
  std::string name() const override { return "slow"; }
  // cv::getNumThreads() in the last Segment call.
  int opencv_threads() const { return opencv_threads_; }

 private:
  int ms_;
  std::atomic<int> opencv_threads_{-1};
};

// A slow segmenter's time per frame for the asynchronous camera-rate tests: `ms`, doubled in
// sanitized builds (extraction and tracking there are 5-20x slower).
// Sanitized builds: GCC (the thread stage) defines __SANITIZE_*__; clang (the address stage, built
// for libFuzzer) only answers __has_feature, so it ran with the Release times. Twice is enough on
// CI's machine; under ThreadSanitizer with another heavy job beside CI's two tests the frames'
// median latency reached 1030 ms against 2 x 500 ms (2026-12-07): keep the machine to CI.
#if defined(__SANITIZE_THREAD__) || defined(__SANITIZE_ADDRESS__)
#define DETSLAM_TEST_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer) || __has_feature(address_sanitizer)
#define DETSLAM_TEST_SANITIZED 1
#endif
#endif

constexpr int SlowSegmenterMs(int ms) {
#ifdef DETSLAM_TEST_SANITIZED
  return 2 * ms;
#else
  return ms;
#endif
}

// Camera rate: a frame's latency less its own extraction and tracking (a new map's initialisation
// is slow under the sanitizers), i.e. the time it waited; waiting for the detector would be most of
// the detector's time.
double WaitedMs(const FrameReport& r) { return r.latency_ms - r.timings.extraction_ms - r.timings.tracking_ms; }

// 60 frames of a static 30 fps sequence at camera rate (threaded, mapping thread), with a segmenter
// that takes `segmenter_ms` per frame; *options: those of the run.
RunSummary RunAtCameraRate(const std::string& name, bool async, int segmenter_ms, RunOptions* options,
                           int* segmenter_opencv_threads = nullptr) {
  const std::string seq = WriteStaticSequence(name, 1, 60);
  const RgbdDataset dataset = RgbdDataset::Open(seq, {});
  const Settings settings = PresetForDataset(seq);
  options->out_dir = TempDir(name + "_run");
  options->threaded = true;
  options->mapping_thread = true;
  options->realtime = true;
  options->async_segmentation = async;
  options->slam = SlamOptionsFromSettings(settings, 42);
  SlowSegmenter segmenter(segmenter_ms);
  RunSummary s = detslam::Run(dataset, settings, *options, nullptr, &segmenter);
  if (segmenter_opencv_threads) *segmenter_opencv_threads = segmenter.opencv_threads();
  return s;
}

// Every offered frame is either processed (in order) or dropped, never both.
void ExpectEveryFrameProcessedOrDropped(const RunSummary& s, int64_t offered) {
  std::vector<int64_t> all = s.dropped_frames;
  int64_t previous = -1;
  for (const FrameReport& r : s.reports) {
    EXPECT_GT(r.index, previous) << "processed out of order";
    previous = r.index;
    all.push_back(r.index);
  }
  std::sort(all.begin(), all.end());
  for (int64_t i = 0; i < offered; ++i) {
    ASSERT_LT(static_cast<size_t>(i), all.size());
    EXPECT_EQ(all[static_cast<size_t>(i)], i) << "a frame neither processed nor dropped, or both";
  }
}

// Camera rate (--realtime) with the segmentation in the frames' path (--sync-segmentation): 60
// frames of a 30 fps sequence are offered over 2 s; a segmenter that takes 100 ms per frame lets
// through about one frame in three, the others are dropped at the camera, not queued: every frame
// is either processed or dropped, the processed ones in order, and latency stays bounded (queued
// frames would wait up to 4 s by the end).
TEST(IntegrationRunner, CameraRateDropsTheFramesThePipelineCannotTake) {
  RunOptions options;
  const int opencv_threads = cv::getNumThreads();
  int segmenter_opencv_threads = -1;
  const RunSummary s =
      RunAtCameraRate("camera_rate", /*async=*/false, 100, &options, &segmenter_opencv_threads);
  // The run's OpenCV threads (RunOptions::camera_rate_opencv_threads) while it lasts, not after.
  EXPECT_EQ(segmenter_opencv_threads, options.camera_rate_opencv_threads);
  EXPECT_EQ(cv::getNumThreads(), opencv_threads);
  EXPECT_EQ(s.offered, 60u);
  EXPECT_EQ(s.frames + s.dropped_frames.size(), 60u);
  EXPECT_GE(s.dropped_frames.size(), 30u) << "frames were queued, not dropped";
  EXPECT_GE(s.camera_s, 1.9) << "frames were not offered at the camera's rate";
  EXPECT_FALSE(s.async_segmentation);
  ExpectEveryFrameProcessedOrDropped(s, 60);
  for (const FrameReport& r : s.reports) {
    EXPECT_GE(r.latency_ms, 100.0) << "frame " << r.index << ": latency shorter than its segmentation";
    EXPECT_LT(r.latency_ms, 2000.0) << "frame " << r.index << " waited in a queue";
    EXPECT_EQ(r.mask_age, -1);
  }
  EXPECT_EQ(s.latency.count, s.frames);
  EXPECT_GE(s.latency_p99_ms, s.latency.median);
  const nlohmann::json j = nlohmann::json::parse(ReadFile((fs::path(options.out_dir) / "run.json").string()));
  EXPECT_EQ(j["mode"], "camera rate (mapping thread)");
  EXPECT_EQ(j["realtime"]["dropped"].get<size_t>(), s.dropped_frames.size());
  EXPECT_TRUE(j["per_frame"][0].contains("latency_ms"));
  const RunLog log = ReadRunLog((fs::path(options.out_dir) / "run.json").string());
  EXPECT_EQ(log.realtime.offered, 60);
  EXPECT_EQ(log.realtime.dropped, static_cast<int64_t>(s.dropped_frames.size()));
}

// Camera rate with asynchronous segmentation (the default): a slow segmenter no longer holds the
// frames up. It segments at most one frame per its time while the others go on with the
// newest masks carried to them: more frames are processed than segmented, latency is below the
// segmenter's time (except the first frame's, which waits for its own masks), and every frame
// knows which frame its masks come from and their age.
TEST(IntegrationRunner, AsynchronousSegmentationDoesNotHoldTheFramesUp) {
  // A segmenter much slower than a frame's extraction and tracking, also on a loaded machine (CI
  // runs two tests at once; a 100 ms segmenter there saw a median latency of 188 ms) and in
  // sanitized builds (extraction and tracking 5-20x slower).
  constexpr int kSegmenterMs = SlowSegmenterMs(500);
  RunOptions options;
  const RunSummary s = RunAtCameraRate("camera_rate_async", /*async=*/true, kSegmenterMs, &options);
  EXPECT_TRUE(s.async_segmentation);
  EXPECT_EQ(s.offered, 60u);
  ExpectEveryFrameProcessedOrDropped(s, 60);
  EXPECT_GE(s.camera_s, 1.9) << "frames were not offered at the camera's rate";
  // The processed frame rate ends at the last frame's pose (offered at 59/30 s), not when the
  // segmentation thread finishes the frame it was segmenting then (up to kSegmenterMs later).
  EXPECT_LE(s.camera_s, 59.0 / 30 + s.latency.max / 1000 + 0.15);
  // At most one segmentation per kSegmenterMs while the camera runs (and two for rounding and the
  // one running when the camera stopped).
  EXPECT_LE(s.frames_segmented, static_cast<size_t>(s.camera_s * 1000 / kSegmenterMs) + 2);
  EXPECT_GE(s.frames_segmented, 2u);
  EXPECT_GT(s.frames, s.frames_segmented) << "the frames waited for the segmenter";
  EXPECT_LT(s.latency.median, kSegmenterMs) << "the frames waited for the segmenter";
  ASSERT_FALSE(s.reports.empty());
  // The start (RunOptions::first_frame_waits_for_masks): the first frame waits for its own masks
  // and is tracked; the frames that arrived before them are dropped, not queued behind it.
  EXPECT_EQ(s.reports.front().index, 0);
  EXPECT_EQ(s.reports.front().mask_age, 0) << "the first frame has its own masks";
  EXPECT_GE(s.reports.front().latency_ms, kSegmenterMs);
  ASSERT_GE(s.reports.size(), 2u);
  EXPECT_LT(WaitedMs(s.reports[1]), kSegmenterMs / 2) << "the frames behind the first were queued";
  EXPECT_GE(s.dropped_frames.size(), static_cast<size_t>(kSegmenterMs / 34 - 1))
      << "the frames arriving while the first waited were not dropped";
  int64_t previous_source = 0;
  int64_t waiting_since = -1;  // the first deferred frame since the last keyframe
  const DetSlamOptions& dyn = options.slam.dynamic;
  for (const FrameReport& r : s.reports) {
    EXPECT_GE(r.mask_source, previous_source) << "frame " << r.index << " used older masks";
    EXPECT_LE(r.mask_source, r.index);
    EXPECT_EQ(r.mask_age, r.index - r.mask_source);
    previous_source = r.mask_source;
    if (r.keyframe_deferred) {
      EXPECT_GT(r.mask_age, dyn.keyframe_max_mask_age);
      EXPECT_GE(r.tracking.num_inliers, dyn.keyframe_defer_min_inliers);
      if (waiting_since < 0) waiting_since = r.index;
      EXPECT_LT(r.index - waiting_since, dyn.keyframe_max_wait) << "frame " << r.index;
    }
    if (r.keyframe) {
      // Masks at most the limit old, or stale ones after waiting keyframe_max_wait frames.
      EXPECT_EQ(r.keyframe_stale_masks, r.mask_age > dyn.keyframe_max_mask_age) << r.index;
      if (r.keyframe_stale_masks && r.tracking.num_inliers >= dyn.keyframe_defer_min_inliers &&
          r.tracking.method != "new map" && r.tracking.method != "init") {  // a map starts at once
        EXPECT_GE(waiting_since, 0) << "keyframe " << r.index << " made without waiting";
        EXPECT_GE(r.index - waiting_since, dyn.keyframe_max_wait) << "keyframe " << r.index;
      }
    }
    if (r.keyframe) waiting_since = -1;
  }
  EXPECT_GT(s.mask_age.max, 0);
  const nlohmann::json j = nlohmann::json::parse(ReadFile((fs::path(options.out_dir) / "run.json").string()));
  EXPECT_EQ(j["realtime"]["asynchronous_segmentation"], true);
  EXPECT_EQ(j["realtime"]["frames_segmented"].get<size_t>(), s.frames_segmented);
  EXPECT_EQ(j["realtime"]["keyframes_stale_masks"].get<size_t>(), s.keyframes_stale_masks);
  EXPECT_EQ(j["per_frame"][1]["mask_age"].get<int>(), s.reports[1].mask_age);
}

// RunOptions::first_frame_waits_for_masks off: the first frame is segmented, not tracked; tracking
// starts with a later frame, its masks carried from the first, without waiting for the detector.
TEST(IntegrationRunner, FirstFrameCanBeLeftUntracked) {
  constexpr int kSegmenterMs = SlowSegmenterMs(300);
  RunOptions options;
  options.first_frame_waits_for_masks = false;
  const RunSummary s = RunAtCameraRate("camera_rate_first_untracked", /*async=*/true, kSegmenterMs, &options);
  ExpectEveryFrameProcessedOrDropped(s, 60);
  ASSERT_FALSE(s.reports.empty());
  ASSERT_FALSE(s.dropped_frames.empty());
  EXPECT_EQ(s.dropped_frames.front(), 0) << "the first frame was processed";
  EXPECT_GT(s.reports.front().index, 0);
  EXPECT_EQ(s.reports.front().mask_source, 0);
  EXPECT_LT(WaitedMs(s.reports.front()), kSegmenterMs / 2)
      << "the first frame tracked waited for the detector (latency " << s.reports.front().latency_ms << " ms)";
}

// A segmenter that records the frames it was asked to segment (no instances).
class FrameListSegmenter : public Segmenter {
 public:
  std::vector<Instance> Segment(const SegmenterInput& in) override {
    frames.push_back(in.index);
    return {};
  }
  std::string name() const override { return "frame list"; }
  std::vector<int64_t> frames;
};

// RunOptions::simulated_detector_frames: the camera-rate masks' timing in a sequential run. With a
// detector that takes 3 frames, it segments frame 0 (the first frame waits for its own masks),
// then frame 1 and every 3rd frame after (1, 4, 7, ...), each one's masks used from the frame 3
// later; every frame is processed, and two runs give the same trajectory.
TEST(IntegrationRunner, SimulatedCameraRateMasksAreDeterministic) {
  const std::string seq = WriteStaticSequence("simulated_masks", 1, 60);
  const RgbdDataset dataset = RgbdDataset::Open(seq, {});
  const Settings settings = PresetForDataset(seq);
  std::vector<std::string> trajectories;
  for (int run = 0; run < 2; ++run) {
    RunOptions options;
    options.out_dir = TempDir("simulated_masks_run" + std::to_string(run));
    options.simulated_detector_frames = 3;
    options.slam = SlamOptionsFromSettings(settings, 42);
    FrameListSegmenter segmenter;
    const RunSummary s = detslam::Run(dataset, settings, options, nullptr, &segmenter);
    std::vector<int64_t> expected = {0};
    for (int64_t i = 1; i < 60; i += 3) expected.push_back(i);
    EXPECT_EQ(segmenter.frames, expected);
    EXPECT_TRUE(s.async_segmentation);
    EXPECT_EQ(s.frames_segmented, expected.size());
    ASSERT_EQ(s.reports.size(), 60u);
    EXPECT_EQ(s.tracked, 60u);
    for (const FrameReport& r : s.reports) {
      // Frames 1-3 carry frame 0's masks; from frame 4 on, the detection started 3-5 frames before.
      const int64_t source = r.index <= 3 ? 0 : 3 * ((r.index - 1) / 3) - 2;
      EXPECT_EQ(r.mask_source, source) << "frame " << r.index;
      EXPECT_EQ(r.mask_age, r.index - source) << "frame " << r.index;
    }
    const nlohmann::json j = nlohmann::json::parse(ReadFile((fs::path(options.out_dir) / "run.json").string()));
    EXPECT_EQ(j["simulated_async_segmentation"]["detector_frames"], 3);
    EXPECT_EQ(j["simulated_async_segmentation"]["frames_segmented"].get<size_t>(), expected.size());
    EXPECT_EQ(j["dynamic_filter"]["geometric_region_frames"], options.camera_rate_region_frames);
    trajectories.push_back(ReadFile((fs::path(options.out_dir) / "trajectory.txt").string()));
  }
  EXPECT_EQ(trajectories[0], trajectories[1]);
  EXPECT_FALSE(trajectories[0].empty());
}

TEST(IntegrationSlamSynthetic, StaticPresetTracksEveryFrameWithinOneCentimetre) {
  const std::string seq = WriteStaticSequence("synth_static", 3, 240);
  const SlamRun run = RunAndEvaluate(seq, TempDir("synth_static_run"), 42);
  EXPECT_EQ(run.summary.tracked, run.summary.frames);
  EXPECT_LE(run.eval.ate.error_m.rmse, 0.01) << "ATE RMSE " << run.eval.ate.error_m.rmse;
  // run.json records every declared key's effective value, and `detslam report` still reads it.
  const std::string run_json = (fs::path(run.trajectory_path).parent_path() / "run.json").string();
  const nlohmann::json j = nlohmann::json::parse(ReadFile(run_json));
  ASSERT_TRUE(j.contains("effective_settings"));
  EXPECT_EQ(j["effective_settings"].size(), DeclaredSettings().size());
  EXPECT_DOUBLE_EQ(j["effective_settings"]["Dynamic.Alpha"].get<double>(), 0.1);
  EXPECT_EQ(j["effective_settings"]["Dynamic.Classes"], nlohmann::json::array({"person"}));
  EXPECT_EQ(j["effective_settings"]["Segmentation.EveryK"].get<int>(), 1);
  EXPECT_EQ(ReadRunLog(run_json).frames, static_cast<int64_t>(run.summary.frames));
}

// The map of a real run (culled keyframes, fused points, covisibility, spanning tree) survives
// save -> load -> save byte for byte, and the loaded map is the run's; a run in localisation mode
// in it tracks the same sequence.
TEST(IntegrationMapFile, ARunsMapSurvivesSaveLoadSave) {
  const std::string seq = WriteStaticSequence("map_file", 2, 120);
  const std::string out = TempDir("map_file_run");
  const RgbdDataset dataset = RgbdDataset::Open(seq, {});
  const Settings settings = PresetForDataset(seq);
  RunOptions options;
  options.out_dir = out;
  options.slam = SlamOptionsFromSettings(settings, 42);
  options.save_map = (fs::path(out) / "map.dslmap").string();
  const RunSummary summary = detslam::Run(dataset, settings, options, nullptr, nullptr);
  EXPECT_EQ(summary.tracked, summary.frames);

  MapFileExpectation expected;
  expected.camera = settings.camera;
  expected.scale = ScaleInfo::Geometric(options.slam.orb.scale_factor, options.slam.orb.num_levels);
  expected.vocabulary_checksum = LoadSharedVocabulary(DefaultVocabularyPath())->Checksum();
  MapFileInfo info;
  const Map map = LoadMapFile(options.save_map, expected, &info);
  EXPECT_EQ(info.keyframes, summary.keyframes);
  EXPECT_EQ(info.landmarks, summary.landmarks);
  EXPECT_EQ(map.place_index().size(), map.NumKeyFrames());
  EXPECT_EQ(info.bytes, summary.map_file_bytes);
  EXPECT_EQ(EncodeMapFile(map, settings.camera, expected.vocabulary_checksum),
            ReadFile(options.save_map));
  const nlohmann::json j = nlohmann::json::parse(ReadFile((fs::path(out) / "run.json").string()));
  EXPECT_EQ(j["map_file"]["bytes"].get<uint64_t>(), info.bytes);

  // Localisation mode in the saved map, same sequence: every frame tracked, no keyframe added,
  // ATE at most 1.1 x the SLAM run's.
  const EvalResult slam_eval =
      EvaluateFiles(dataset.groundtruth_path(), (fs::path(out) / "trajectory.txt").string(), seq, {});
  RunOptions loc = options;
  loc.out_dir = TempDir("map_file_localization");
  loc.save_map.clear();
  loc.load_map = options.save_map;
  loc.slam.localization = true;
  const RunSummary localized = detslam::Run(dataset, settings, loc, nullptr, nullptr);
  EXPECT_EQ(localized.tracked, localized.frames);
  EXPECT_EQ(localized.keyframes, summary.keyframes);
  EXPECT_EQ(localized.loaded_keyframes, summary.keyframes);
  const EvalResult loc_eval = EvaluateFiles(
      dataset.groundtruth_path(), (fs::path(loc.out_dir) / "trajectory.txt").string(), seq, {});
  EXPECT_LE(loc_eval.ate.error_m.rmse, 1.1 * slam_eval.ate.error_m.rmse)
      << "localisation " << loc_eval.ate.error_m.rmse << " m, SLAM " << slam_eval.ate.error_m.rmse;
}

}  // namespace
}  // namespace detslam
