// Several maps (the atlas) on the roam preset with a covered lens: while the lens is covered the
// camera turns towards ground it has never seen, so relocalisation cannot succeed afterwards. A new
// map must start from the first frame after the cover, the camera's return to its start must merge
// it into the first map (welding the seam), and trajectory.txt (the main map) must then hold every
// frame that is not black, as accurately as the uncovered twin's.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <utility>

#include "detslam/eval/ate.h"
#include "detslam/pipeline/slam_system.h"
#include "detslam/synth/sequence.h"

namespace detslam {
namespace {

struct AtlasRun {
  int frames = 0, black = 0;
  int new_maps = 0;          // frames that started a new map after tracking was lost
  int first_map_after = -1;  // map of the first frame tracked after the cover
  int first_keyframes = 0;    // keyframes made in the first 2 s (60 frames) of the run
  int new_map_keyframes = 0;  // keyframes made in the first 2 s of a map started after a loss
  int new_map_frame = -1;     // the frame that started it
  int merges = 0;
  int welded = 0;  // keyframes the merges' seam bundle adjustments optimised
  size_t main_frames = 0;  // frames in the main map at the end
  size_t maps_left = 0;
  double ate_m = 0;
};

// Runs the sequence without and with its cover (so.cover_*), one SLAM system each, in lockstep:
// a frame the cover does not black out is the same in both, so it is rendered once.
std::pair<AtlasRun, AtlasRun> RunRoam(const SynthOptions& covered_options) {
  SynthOptions plain_options = covered_options;
  plain_options.cover_start_s = 0.0;
  plain_options.cover_seconds = 0.0;
  const SyntheticSequence plain_seq(plain_options), covered_seq(covered_options);
  const SynthOptions* options[2] = {&plain_options, &covered_options};
  SlamSystem plain_slam(plain_seq.camera(), SlamOptions()), covered_slam(plain_seq.camera(), SlamOptions());
  SlamSystem* slams[2] = {&plain_slam, &covered_slam};
  Trajectory gt;
  AtlasRun runs[2];
  for (int k = 0; k < plain_seq.size(); ++k) {
    const SynthFrame plain = plain_seq.Render(k);
    const SynthFrame covered = covered_options.Covered(k) ? covered_seq.Render(k) : plain;
    const SynthFrame* frames[2] = {&plain, &covered};
    for (int i = 0; i < 2; ++i) {
      const SynthOptions& so = *options[i];
      const SynthFrame& f = *frames[i];
      AtlasRun& run = runs[i];
      const cv::Mat gray = f.Gray(), depth = f.DepthMetres(plain_seq.camera().depth_map_factor);
      const FrameReport r = slams[i]->ProcessFrame(k, f.stamp, gray, depth);
      ++run.frames;
      run.black += so.Covered(k) ? 1 : 0;
      run.new_maps += r.tracking.new_map ? 1 : 0;
      if (r.tracking.new_map && run.new_map_frame < 0) run.new_map_frame = k;
      run.first_keyframes += k < 60 && r.keyframe ? 1 : 0;
      run.new_map_keyframes +=
          run.new_map_frame >= 0 && k < run.new_map_frame + 60 && r.keyframe ? 1 : 0;
      if (k >= 240 && !so.Covered(k) && run.first_map_after < 0 && r.tracking.pose_valid)
        run.first_map_after = r.map_id;
    }
    gt.push_back({plain.stamp, plain.world_from_cam});
  }
  for (int i = 0; i < 2; ++i) {
    AtlasRun& run = runs[i];
    run.merges = slams[i]->maps_merged();
    for (const LoopRecord& loop : slams[i]->loops()) run.welded += loop.merge ? loop.welded_keyframes : 0;
    const MapTrajectories all = slams[i]->FrameTrajectories();
    run.maps_left = all.by_map.size();
    run.main_frames = all.by_map.at(all.main_map).size();
    run.ate_m = ComputeAte(gt, all.by_map.at(all.main_map), AteOptions()).error_m.rmse;
  }
  return {runs[0], runs[1]};
}

TEST(IntegrationAtlas, CoveredLensStartsANewMapThatMergesOnTheWayBack) {
  SynthOptions so;
  so.preset = "roam";
  so.seed = 2;
  so.people = false;  // no segmenter here: the people are the dynamic benchmarks' business
  so.cover_start_s = 8.0;
  so.cover_seconds = 2.0;
  const auto [plain, covered] = RunRoam(so);

  EXPECT_EQ(plain.new_maps, 0);
  EXPECT_EQ(plain.main_frames, static_cast<size_t>(plain.frames));
  EXPECT_EQ(covered.black, 60);
  EXPECT_EQ(covered.new_maps, 1);
  EXPECT_EQ(covered.first_map_after, 1);  // relocalisation in map 0 cannot succeed there
  // The new map is mapped as densely as the first one at its start: its keyframe rule counts its
  // own keyframes, not the atlas's (with the atlas's count, it made 1 keyframe in its first 2 s
  // here and the covered ATE was 7.6 mm; 6 now, as the first map, and 2.1 mm).
  EXPECT_GE(covered.new_map_keyframes, 3) << "the first map made " << covered.first_keyframes;
  std::printf("keyframes in the first 2 s: first map %d, new map %d; ATE covered %.1f mm, plain %.1f mm\n",
              covered.first_keyframes, covered.new_map_keyframes, 1000 * covered.ate_m, 1000 * plain.ate_m);
  EXPECT_EQ(covered.merges, 1);
  // Welded: the seam's window on both sides bundle-adjusted (then fixed in the pose graph).
  EXPECT_GE(covered.welded, 2);
  EXPECT_EQ(covered.maps_left, 1u);
  // Every frame that is not black ends up in the main map.
  EXPECT_GE(covered.main_frames, static_cast<size_t>(0.95 * (covered.frames - covered.black)));
  EXPECT_LE(covered.ate_m, 1.5 * plain.ate_m + 0.002)
      << "ATE covered " << covered.ate_m << " m, plain " << plain.ate_m << " m";
}

// The look-alike room (two parts with the same textures in other layouts) with its passage hidden
// by the cover: the camera comes back from the cover in the second part, where every place looks
// like one of the first map's. On this tuning seed ORB-SLAM3's acceptance rule (10 PnP inliers,
// 50 after the projection search) relocalised the first frame after the cover into the first map
// about 4.9 m from its true place. A relocalisation (or merge) into the first map may happen only
// where it is true; otherwise a new map starts.
TEST(IntegrationAtlas, LookAlikePlaceIsNotARelocalisation) {
  SynthOptions so;
  so.preset = "lookalike";
  so.seed = 3;
  so.realism = SynthRealism::kRealistic;  // what `detslam synth` writes by default
  so.people = false;
  so.frames = 840;
  so.cover_start_s = 20.0;
  so.cover_seconds = 7.0;
  const SyntheticSequence seq(so);
  SlamSystem slam(seq.camera(), SlamOptions());
  Trajectory gt;
  int first_after = -1, first_map_after = -1;
  for (int k = 0; k < seq.size(); ++k) {
    const SynthFrame f = seq.Render(k);
    const FrameReport r = slam.ProcessFrame(
        k, f.stamp, f.Gray(), f.DepthMetres(seq.camera().depth_map_factor));
    if (!so.Covered(k) && k >= 600 && first_after < 0 && r.tracking.pose_valid) {
      first_after = k;
      first_map_after = r.map_id;
    }
    gt.push_back({f.stamp, f.world_from_cam});
  }
  ASSERT_GE(first_after, 0) << "no frame tracked after the cover";
  // Every pose after the cover that landed in the main map (by relocalisation or a merge) is
  // where ground truth has it, relative to the main map's first frame.
  const Trajectory main = slam.FrameTrajectory();
  ASSERT_FALSE(main.empty());
  auto gt_at = [&](Timestamp t) {
    for (const StampedPose& p : gt)
      if (p.stamp == t) return p.world_from_cam;
    ADD_FAILURE() << "no ground truth at " << t.Seconds();
    return Rigid3d();
  };
  const Rigid3d gt_from_map = gt_at(main.front().stamp) * main.front().world_from_cam.Inverse();
  int checked = 0, misplaced = 0;
  double worst = 0;
  for (const StampedPose& p : main) {
    if (p.stamp.Seconds() < gt[static_cast<size_t>(first_after)].stamp.Seconds()) continue;
    const double err =
        ((gt_from_map * p.world_from_cam).translation() - gt_at(p.stamp).translation()).norm();
    misplaced += err > 0.5 ? 1 : 0;
    worst = std::max(worst, err);
    ++checked;
  }
  EXPECT_EQ(misplaced, 0) << misplaced << " of " << checked
                          << " poses after the cover in the first map are more than 0.5 m from "
                             "their true place (worst "
                          << worst << " m)";
  RecordProperty("first_frame_after_cover", first_after);
  RecordProperty("its_map", first_map_after);
  RecordProperty("main_map_poses_after_cover", checked);
}

}  // namespace
}  // namespace detslam
