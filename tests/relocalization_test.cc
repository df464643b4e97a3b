// Relocalisation: the camera is "kidnapped" (a run of blank frames, tracking is lost) and must
// relocalise against the map when valid frames return, with poses consistent with before.
#include <gtest/gtest.h>

#include "detslam/eval/ate.h"
#include "detslam/pipeline/slam_system.h"
#include "detslam/synth/sequence.h"

namespace detslam {
namespace {

TEST(IntegrationRelocalization, RecoversAfterBlankFrames) {
  SynthOptions so;
  so.preset = "static";
  so.seed = 4;
  so.frames = 160;
  const SyntheticSequence seq(so);
  SlamOptions options;
  SlamSystem slam(seq.camera(), options);
  Trajectory gt;
  bool lost_seen = false, relocalized = false;
  int tracked_after_gap = 0;
  for (int k = 0; k < seq.size(); ++k) {
    const SynthFrame f = seq.Render(k);
    cv::Mat gray = f.Gray(), depth = f.DepthMetres(seq.camera().depth_map_factor);
    const bool blank = k >= 80 && k < 90;  // the sensor is covered: no texture, no depth
    if (blank) {
      gray.setTo(0);
      depth.setTo(0);
    }
    const FrameReport r = slam.ProcessFrame(k, f.stamp, gray, depth);
    if (blank) lost_seen |= !r.tracking.pose_valid;
    if (k >= 90) {
      relocalized |= r.tracking.relocalized;
      tracked_after_gap += r.tracking.pose_valid ? 1 : 0;
    }
    gt.push_back({f.stamp, f.world_from_cam});
  }
  EXPECT_TRUE(lost_seen);
  EXPECT_TRUE(relocalized);
  EXPECT_GE(tracked_after_gap, 65);  // of 70 frames after the gap
  const AteResult ate = ComputeAte(gt, slam.FrameTrajectory(), AteOptions());
  EXPECT_LE(ate.error_m.rmse, 0.02) << "ATE RMSE " << ate.error_m.rmse;
}

}  // namespace
}  // namespace detslam
