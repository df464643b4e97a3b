// Loop closing on the synthetic `loop` preset (the camera walks around the room and comes back to
// its start): the loop must be detected by appearance (shipped vocabulary, no position gate) and
// closed only once 3 keyframes agree on it, every frame tracked, and the trajectory must be far
// more accurate than with loop closing off.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <optional>
#include <thread>
#include <vector>

#include "detslam/eval/ate.h"
#include "detslam/pipeline/bounded_queue.h"
#include "detslam/pipeline/slam_system.h"
#include "detslam/synth/sequence.h"

namespace detslam {
namespace {

struct LoopRun {
  int tracked = 0;
  int frames = 0;
  int loops = 0;
  int min_agreeing = 0;  // fewest keyframes that agreed on a closed loop
  double ate_m = 0;
};

struct LoopConfig {
  bool loop_closing = false;
  bool global_ba_thread = false;
  // Local mapping and loop closing each in a thread of its own, fed by queues, as the threaded
  // runner with a mapping thread runs them (SlamOptions::loop_thread); implies global_ba_thread.
  bool threads = false;
};

// The local-mapping and loop-closing threads of a `threads` configuration.
class MappingThreads {
 public:
  explicit MappingThreads(SlamSystem* slam)
      : mapping_([this, slam] {
          while (std::optional<KeyFrameId> kf = keyframes_.Pop()) {
            FrameReport unused;
            slam->MapKeyFrame(*kf, &unused);
            to_close_.Push(*kf);
          }
          to_close_.Close();
        }),
        closing_([this, slam] {
          while (std::optional<KeyFrameId> kf = to_close_.Pop()) {
            FrameReport unused;
            slam->CloseLoops(*kf, &unused);
            ++closed_;
          }
        }) {}
  void Map(KeyFrameId kf) { keyframes_.Push(kf); }
  // Waits until every keyframe given to Map was locally mapped and through loop closing; returns
  // how many went through loop closing.
  int Finish() {
    keyframes_.Close();
    mapping_.join();
    closing_.join();
    return closed_;
  }

 private:
  BoundedQueue<KeyFrameId> keyframes_{8}, to_close_{1024};
  int closed_ = 0;
  std::thread mapping_, closing_;
};

// Runs one SLAM system per configuration over the sequence, in lockstep: each frame is rendered
// once and given to every system (rendering is most of a synthetic run's time).
std::vector<LoopRun> RunLoopPreset(const SyntheticSequence& seq,
                                   const std::vector<LoopConfig>& configs) {
  std::vector<std::unique_ptr<SlamSystem>> systems;
  std::vector<std::unique_ptr<MappingThreads>> threads;
  for (const LoopConfig& c : configs) {
    SlamOptions options;
    options.loop.enabled = c.loop_closing;
    options.global_ba_thread = c.global_ba_thread || c.threads;
    options.loop_thread = c.threads;
    systems.push_back(std::make_unique<SlamSystem>(seq.camera(), options));
    threads.push_back(c.threads ? std::make_unique<MappingThreads>(systems.back().get())
                                : nullptr);
  }
  Trajectory gt;
  std::vector<LoopRun> runs(configs.size());
  for (int k = 0; k < seq.size(); ++k) {
    const SynthFrame f = seq.Render(k);
    const cv::Mat gray = f.Gray(), depth = f.DepthMetres(seq.camera().depth_map_factor);
    for (size_t i = 0; i < systems.size(); ++i) {
      FrameReport r;
      if (threads[i]) {
        Frame frame = systems[i]->ExtractFrame(k, f.stamp, gray, depth, cv::Mat(), &r);
        const KeyFrameId kf = systems[i]->TrackFrame(std::move(frame), &r);
        if (kf != kNoKeyFrame) threads[i]->Map(kf);
      } else {
        r = systems[i]->ProcessFrame(k, f.stamp, gray, depth);
      }
      LoopRun& run = runs[i];
      run.tracked += r.tracking.pose_valid ? 1 : 0;
      if (r.loop_closed)
        run.min_agreeing = run.min_agreeing ? std::min(run.min_agreeing, r.loop_agreeing)
                                            : r.loop_agreeing;
      ++run.frames;
    }
    gt.push_back({f.stamp, f.world_from_cam});
  }
  for (size_t i = 0; i < systems.size(); ++i) {
    SlamSystem& slam = *systems[i];
    if (threads[i]) {
      // Every keyframe local mapping finished went through loop closing, in its own thread.
      const int closed = threads[i]->Finish();
      EXPECT_EQ(slam.loop_closing_times_ms().size(), static_cast<size_t>(closed));
      EXPECT_EQ(slam.mapping_times_ms().size(), static_cast<size_t>(closed));
    }
    slam.WaitForGlobalBundleAdjustment();
    runs[i].loops = slam.loops_closed();
    EXPECT_EQ(slam.loops().size(), static_cast<size_t>(runs[i].loops));
    // In the loop-closing thread only, the loop's keyframe came from a rendered frame: count it.
    if (threads[i]) runs[i].min_agreeing = 0;
    for (const LoopRecord& loop : slam.loops()) {
      if (threads[i]) {
        // Corrected later than its keyframe's frame (tracking went on), while local mapping
        // was held.
        EXPECT_GE(loop.corrected_after_frame, loop.frame);
        EXPECT_GT(loop.mapping_held_ms, 0.0);
        runs[i].min_agreeing = runs[i].min_agreeing
                                   ? std::min(runs[i].min_agreeing, loop.agreeing)
                                   : loop.agreeing;
      } else {
        // Mapping in line: the loop is corrected right after its keyframe's frame was tracked,
        // and nothing was held.
        EXPECT_EQ(loop.corrected_after_frame, loop.frame);
        EXPECT_EQ(loop.mapping_held_ms, 0.0);
      }
      EXPECT_GT(loop.map_locked_ms, 0.0);
      // The relative pose the loop asserts is the true one, up to the drift between the two
      // views (1 mm on this run); a loop taken on a look-alike would be metres off.
      const Rigid3d true_rel =
          gt[static_cast<size_t>(loop.candidate_frame)].world_from_cam.Inverse() *
          gt[static_cast<size_t>(loop.frame)].world_from_cam;
      const double rel_error_m =
          (loop.candidate_from_keyframe.translation() - true_rel.translation()).norm();
      EXPECT_LT(rel_error_m, 0.05) << "loop at frame " << loop.frame << " with frame "
                                   << loop.candidate_frame;
    }
    // Every global BA that was not stopped by a newer loop applied its solution, after the loop.
    const std::vector<int64_t> applied = slam.global_ba_applied_after_frames();
    EXPECT_EQ(applied.size(),
              static_cast<size_t>(slam.global_ba_runs() - slam.global_ba_stopped()));
    if (!applied.empty() && !slam.loops().empty()) {
      EXPECT_GE(applied.front(), slam.loops().front().frame);
    }
    runs[i].ate_m = ComputeAte(gt, slam.FrameTrajectory(), AteOptions()).error_m.rmse;
  }
  return runs;
}

TEST(IntegrationLoopClosing, ClosesTheLoopOfTheLoopPreset) {
  SynthOptions so;
  so.preset = "loop";
  so.seed = 1;
  // One 32 s lap and 8 s over the start again: a loop is accepted once 3 keyframes agree on it
  // (the keyframes that see the start again are sparse, so the camera must stay on known ground
  // for a few of them).
  so.frames = 1200;
  const SyntheticSequence seq(so);
  // Without loop closing, with it, with the global bundle adjustment in a thread of its own
  // (as with a mapping thread: frames go on while it runs, its result is merged), and with local
  // mapping, loop closing and the global BA each in a thread of its own (the threaded runner's).
  const std::vector<LoopRun> runs =
      RunLoopPreset(seq, {{false, false}, {true, false}, {true, true}, {true, true, true}});
  const LoopRun& without = runs[0];
  const LoopRun& with = runs[1];
  const LoopRun& threaded = runs[2];
  const LoopRun& loop_thread = runs[3];
  EXPECT_EQ(without.loops, 0);
  EXPECT_GE(with.loops, 1);
  EXPECT_GE(with.min_agreeing, SlamOptions().loop.consistent_detections);
  EXPECT_EQ(SlamOptions().loop.consistent_detections, 3);
  EXPECT_EQ(with.tracked, with.frames);
  EXPECT_LT(with.ate_m, 0.6 * without.ate_m) << "ATE with loop closing " << with.ate_m << " m, without " << without.ate_m << " m";
  // The loop must be as well corrected by the global bundle adjustment thread.
  EXPECT_GE(threaded.loops, 1);
  EXPECT_EQ(threaded.tracked, threaded.frames);
  EXPECT_LT(threaded.ate_m, 0.6 * without.ate_m) << "ATE with the global BA thread " << threaded.ate_m << " m";
  // And by the loop-closing thread, on as many agreeing keyframes.
  EXPECT_GE(loop_thread.loops, 1);
  EXPECT_GE(loop_thread.min_agreeing, SlamOptions().loop.consistent_detections);
  EXPECT_EQ(loop_thread.tracked, loop_thread.frames);
  EXPECT_LT(loop_thread.ate_m, 0.6 * without.ate_m) << "ATE with the loop-closing thread " << loop_thread.ate_m << " m";
}

}  // namespace
}  // namespace detslam
