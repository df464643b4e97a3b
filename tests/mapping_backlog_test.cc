// Local mapping that lags behind tracking (a threaded run whose mapping thread is busy), driven
// by hand in one thread so that it is deterministic: the mapper takes the waiting keyframes only
// every 15 frames, and not at all for 5 s in the middle (a stall, e.g. a long loop correction).
// Tracking must then queue at most 3 keyframes besides the one being mapped
// (ORB-SLAM3's rule for RGB-D), every frame must still be tracked, and the mapper must map every
// keyframe of a burst but the last without fusion, bundle adjustment or keyframe culling.
#include <gtest/gtest.h>

#include <deque>

#include "detslam/eval/ate.h"
#include "detslam/pipeline/slam_system.h"
#include "detslam/synth/sequence.h"

namespace detslam {
namespace {

TEST(IntegrationMappingBacklog, ABusyMapperGetsFewKeyFramesAndMapsBurstsWithoutBa) {
  SynthOptions so;
  so.preset = "walking_xyz";
  so.seed = 5;
  so.frames = 240;
  so.people = false;
  const SyntheticSequence seq(so);
  SlamSystem lagging(seq.camera(), SlamOptions()), sequential(seq.camera(), SlamOptions());
  constexpr int kMapEvery = 15;
  std::deque<KeyFrameId> waiting;  // made by TrackFrame, not yet given to MapKeyFrame
  size_t most_waiting = 0;
  int tracked = 0, lagging_keyframes = 0, sequential_keyframes = 0, bursts = 0, interrupts = 0;
  Trajectory gt;
  for (int k = 0; k < seq.size(); ++k) {
    const SynthFrame f = seq.Render(k);
    const cv::Mat gray = f.Gray(), depth = f.DepthMetres(seq.camera().depth_map_factor);
    gt.push_back({f.stamp, f.world_from_cam});
    sequential_keyframes += sequential.ProcessFrame(k, f.stamp, gray, depth).keyframe ? 1 : 0;

    FrameReport report;
    Frame frame = lagging.ExtractFrame(k, f.stamp, gray, depth, cv::Mat(), &report);
    const KeyFrameId kf = lagging.TrackFrame(std::move(frame), &report);
    tracked += report.tracking.pose_valid ? 1 : 0;
    interrupts += report.tracking.interrupt_local_ba ? 1 : 0;
    if (kf != kNoKeyFrame) {
      ++lagging_keyframes;
      waiting.push_back(kf);
    }
    most_waiting = std::max(most_waiting, waiting.size());
    const bool stalled = k >= 45 && k < 195;
    if ((k % kMapEvery == kMapEvery - 1 && !stalled) || k + 1 == seq.size()) {
      bursts += waiting.empty() ? 0 : 1;
      while (!waiting.empty()) {
        FrameReport unused;
        lagging.MapKeyFrame(waiting.front(), &unused);
        waiting.pop_front();
      }
    }
  }
  EXPECT_EQ(tracked, seq.size());
  // One being mapped (the mapper counts as busy from the first) and at most 3 queued behind it.
  EXPECT_LE(most_waiting, 4u);
  EXPECT_EQ(most_waiting, 4u);  // reached during the stall
  EXPECT_GT(interrupts, 0);     // frames that wanted a keyframe while it was busy said so
  EXPECT_LT(lagging_keyframes, sequential_keyframes);
  // Every keyframe of a burst but its last was mapped while others waited.
  EXPECT_EQ(lagging.keyframes_mapped_in_burst(), lagging_keyframes - bursts);
  EXPECT_EQ(sequential.keyframes_mapped_in_burst(), 0);
  const double ate_lagging = ComputeAte(gt, lagging.FrameTrajectory(), AteOptions()).error_m.rmse;
  const double ate_sequential =
      ComputeAte(gt, sequential.FrameTrajectory(), AteOptions()).error_m.rmse;
  EXPECT_LT(ate_sequential, 0.01);
  EXPECT_LT(ate_lagging, 0.02) << "sequential " << ate_sequential;
}

}  // namespace
}  // namespace detslam
