#include "detslam/eval/rpe.h"

#include <gtest/gtest.h>

#include <cmath>

#include "detslam/eval/eval_test_util.h"

namespace detslam {
namespace {

using eval_test::MakeTrajectory;
using eval_test::RotZ;
using eval_test::Sec;
using eval_test::Wiggle;

TEST(Rpe, IdenticalTrajectoriesGiveZeroAndDropThePairEndingOnTheLastPose) {
  // 50 estimates at 10 Hz over 4.9 s, delta 1 s: j = i + 10. Pairs with j = 49 (the last pose) or
  // beyond (clamped to the last pose) are dropped, so i = 0..38 remain.
  const Trajectory gt = MakeTrajectory(1000, 100, 500, Wiggle);
  const Trajectory est = MakeTrajectory(1000, 10, 50, Wiggle);
  const RpeResult r = ComputeRpe(gt, est, RpeOptions{});
  ASSERT_EQ(r.pairs.size(), 39u);
  EXPECT_EQ(r.pairs.front().est_to, Sec(1001.0));
  EXPECT_EQ(r.pairs.back().est_from, Sec(1003.8));
  EXPECT_NEAR(r.trans_m.max, 0.0, 1e-9);
  EXPECT_NEAR(r.rot_deg.max, 0.0, 1e-5);  // arccos near 1 loses half the digits
}

TEST(Rpe, RigidlyMovedCopyGivesZero) {
  const Trajectory gt = MakeTrajectory(0, 30, 150, Wiggle);
  Trajectory est = gt;
  const Rigid3d other_from_world = RotZ(-2.0, Eigen::Vector3d(1, 2, 3));
  for (StampedPose& p : est) p.world_from_cam = other_from_world * p.world_from_cam;
  const RpeResult r = ComputeRpe(gt, est, RpeOptions{});
  EXPECT_GT(r.pairs.size(), 100u);
  EXPECT_NEAR(r.trans_m.max, 0.0, 1e-9);
  EXPECT_NEAR(r.rot_deg.max, 0.0, 1e-5);
}

TEST(Rpe, ConstantVelocityErrorGivesKnownRpe) {
  // gt moves 1 m/s along x, the estimate 1.1 m/s: over every 1 s window the error is 0.1 m.
  const auto gt_pose = [](double t) { return RotZ(0, Eigen::Vector3d(t, 0, 0)); };
  const auto est_pose = [](double t) { return RotZ(0, Eigen::Vector3d(1.1 * t, 0, 0)); };
  const RpeResult r = ComputeRpe(MakeTrajectory(0, 100, 1000, gt_pose),
                                 MakeTrajectory(0, 30, 300, est_pose), RpeOptions{});
  ASSERT_GT(r.pairs.size(), 200u);
  EXPECT_NEAR(r.trans_m.min, 0.1, 1e-9);
  EXPECT_NEAR(r.trans_m.max, 0.1, 1e-9);
  EXPECT_NEAR(r.TransPerSecond().rmse, 0.1, 1e-9);
  EXPECT_NEAR(r.rot_deg.max, 0.0, 1e-5);

  // Yaw rate error of 0.05 rad/s in place: 0.05 rad = 2.864789 deg per 1 s window.
  const auto gt_rot = [](double t) { return RotZ(0.5 * t, Eigen::Vector3d::Zero()); };
  const auto est_rot = [](double t) { return RotZ(0.55 * t, Eigen::Vector3d::Zero()); };
  const RpeResult rr = ComputeRpe(MakeTrajectory(0, 100, 1000, gt_rot),
                                  MakeTrajectory(0, 30, 300, est_rot), RpeOptions{});
  EXPECT_NEAR(rr.rot_deg.mean, 0.05 * 180 / M_PI, 1e-7);
  EXPECT_NEAR(rr.rot_deg.std, 0.0, 1e-7);
  EXPECT_NEAR(rr.trans_m.max, 0.0, 1e-9);
  // A 2 s window doubles the error; per second it is the same.
  RpeOptions two;
  two.delta = 2.0;
  const RpeResult r2 = ComputeRpe(MakeTrajectory(0, 100, 1000, gt_rot),
                                  MakeTrajectory(0, 30, 300, est_rot), two);
  EXPECT_NEAR(r2.rot_deg.mean, 0.1 * 180 / M_PI, 1e-7);
  EXPECT_NEAR(r2.RotPerSecond().mean, 0.05 * 180 / M_PI, 1e-7);
}

TEST(Rpe, PairsWhoseGroundTruthIsMissingAreDropped) {
  // gt at 100 Hz over 0..10 s without (3, 4): estimates at 3.1..3.9 s are more than 2 x 0.01 s
  // from any gt stamp. Of the 89 pairs (i = 0..88), those starting at 3.1..3.9 s and those ending
  // there (starting at 2.1..2.9 s) are dropped: 89 - 18 = 71.
  Trajectory gt;
  for (int k = 0; k <= 1000; ++k) {
    if (k > 300 && k < 400) continue;
    gt.push_back({Sec(k * 0.01), Wiggle(k * 0.01)});
  }
  const Trajectory est = MakeTrajectory(0, 10, 100, Wiggle);
  const RpeResult r = ComputeRpe(gt, est, RpeOptions{});
  EXPECT_EQ(r.pairs.size(), 71u);
  for (const RpePair& p : r.pairs) {
    EXPECT_FALSE(p.est_from > Sec(3.05) && p.est_from < Sec(3.95));
    EXPECT_FALSE(p.est_to > Sec(3.05) && p.est_to < Sec(3.95));
  }
}

TEST(Rpe, PerFrameDeltaUsesConsecutivePoses) {
  const auto gt_pose = [](double t) { return RotZ(0, Eigen::Vector3d(t, 0, 0)); };
  const auto est_pose = [](double t) { return RotZ(0, Eigen::Vector3d(1.1 * t, 0, 0)); };
  RpeOptions frames;
  frames.unit = RpeDeltaUnit::kFrames;
  frames.delta = 1;
  const RpeResult r = ComputeRpe(MakeTrajectory(0, 100, 300, gt_pose),
                                 MakeTrajectory(0, 25, 60, est_pose), frames);
  EXPECT_EQ(r.pairs.size(), 58u);  // i = 0..57; the pair ending on the last pose is dropped
  EXPECT_EQ(r.pairs[3].est_to, Sec(4.0 / 25));
  EXPECT_NEAR(r.trans_m.mean, 0.1 / 25, 1e-9);
  EXPECT_FALSE(r.per_second());
}

TEST(Rpe, TiesGoToTheEarlierStampAndBadOptionsAreRejected) {
  const std::vector<Timestamp> stamps = {Sec(1.0), Sec(2.0), Sec(3.0)};
  EXPECT_EQ(ClosestIndex(stamps, Sec(1.5)), 0u);
  EXPECT_EQ(ClosestIndex(stamps, Sec(1.5001)), 1u);
  EXPECT_EQ(ClosestIndex(stamps, Sec(-4)), 0u);
  EXPECT_EQ(ClosestIndex(stamps, Sec(9)), 2u);
  std::string why;
  EXPECT_FALSE((RpeOptions{0.0, RpeDeltaUnit::kSeconds, 0.0}.Check(&why)));
  EXPECT_FALSE((RpeOptions{1.5, RpeDeltaUnit::kFrames, 0.0}.Check(&why)));
  EXPECT_TRUE((RpeOptions{3, RpeDeltaUnit::kFrames, 0.0}.Check(&why)));
}

TEST(Rpe, NoOverlapGivesNoPairs) {
  const RpeResult r = ComputeRpe(MakeTrajectory(0, 100, 300, Wiggle),
                                 MakeTrajectory(50, 30, 90, Wiggle), RpeOptions{});
  EXPECT_TRUE(r.pairs.empty());
  EXPECT_EQ(r.trans_m.count, 0u);
}

}  // namespace
}  // namespace detslam
