#include "detslam/eval/ate.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "detslam/core/check.h"
#include "detslam/eval/eval_test_util.h"

namespace detslam {
namespace {

using eval_test::MakeTrajectory;
using eval_test::Sec;
using eval_test::Wiggle;

TEST(Ate, IdenticalTrajectoriesGiveZero) {
  const Trajectory gt = MakeTrajectory(1000, 30, 90, Wiggle);
  const AteResult r = ComputeAte(gt, gt, AteOptions{});
  EXPECT_EQ(r.pairs.size(), 90u);
  EXPECT_EQ(r.error_m.count, 90u);
  EXPECT_NEAR(r.error_m.rmse, 0.0, 1e-9);
  EXPECT_NEAR(r.error_m.max, 0.0, 1e-9);
}

TEST(Ate, RigidlyMovedCopyGivesZeroAndRecoversTheMotion) {
  const Trajectory gt = MakeTrajectory(1000, 30, 90, Wiggle);
  const Rigid3d other_from_world = eval_test::RotZ(1.2, Eigen::Vector3d(5, -3, 2));
  Trajectory est = gt;
  for (StampedPose& p : est) p.world_from_cam = other_from_world * p.world_from_cam;
  const AteResult r = ComputeAte(gt, est, AteOptions{});
  EXPECT_NEAR(r.error_m.rmse, 0.0, 1e-9);
  const Rigid3d expect = other_from_world.Inverse();
  EXPECT_NEAR((r.gt_from_est.b_from_a.translation() - expect.translation()).norm(), 0, 1e-9);
  EXPECT_NEAR(r.gt_from_est.b_from_a.rotation().angularDistance(expect.rotation()), 0, 1e-9);
  // The aligned estimate lands on the ground truth.
  EXPECT_NEAR((r.pairs[40].est_aligned - gt[40].world_from_cam.translation()).norm(), 0, 1e-9);
}

TEST(Ate, KnownOffsetOnTwoOfEightFramesGivesKnownStatistics) {
  // Ground truth on the 8 corners of a cube (full rank). Two opposite corners are offset by d
  // (|d| = 0.5); their centroid is the cube centre, so the optimal rotation stays the identity and
  // the optimal translation is -p d with p = 2/8. Errors: 0.5 * 0.75 = 0.375 on the two frames,
  // 0.5 * 0.25 = 0.125 on the six others.
  Trajectory gt, est;
  int k = 0;
  for (int x : {-1, 1}) {
    for (int y : {-1, 1}) {
      for (int z : {-1, 1}) {
        const Rigid3d pose = eval_test::RotZ(0.1 * k, Eigen::Vector3d(x, y, z));
        gt.push_back({Sec(10 + 0.1 * k), pose});
        const bool offset = (x == y && y == z);
        est.push_back({Sec(10 + 0.1 * k + 0.005),
                       Rigid3d(pose.rotation(), pose.translation() +
                                                    (offset ? Eigen::Vector3d(0.3, 0, -0.4)
                                                            : Eigen::Vector3d::Zero()))});
        ++k;
      }
    }
  }
  const AteResult r = ComputeAte(gt, est, AteOptions{});
  ASSERT_EQ(r.pairs.size(), 8u);
  EXPECT_NEAR(r.error_m.rmse, 0.5 * std::sqrt(0.25 * 0.75), 1e-12);
  EXPECT_NEAR(r.error_m.mean, (2 * 0.375 + 6 * 0.125) / 8, 1e-12);
  EXPECT_NEAR(r.error_m.median, 0.125, 1e-12);
  EXPECT_NEAR(r.error_m.min, 0.125, 1e-12);
  EXPECT_NEAR(r.error_m.max, 0.375, 1e-12);
  // Population std: sqrt((6 * 0.0625^2 + 2 * 0.1875^2) / 8).
  EXPECT_NEAR(r.error_m.std, std::sqrt((6 * 0.0625 * 0.0625 + 2 * 0.1875 * 0.1875) / 8), 1e-12);
}

TEST(Ate, ScaleAlignmentRemovesAScaleError) {
  const Trajectory gt = MakeTrajectory(0, 10, 50, Wiggle);
  Trajectory est = gt;
  for (StampedPose& p : est) {
    p.world_from_cam = Rigid3d(p.world_from_cam.rotation(), 0.5 * p.world_from_cam.translation());
  }
  AteOptions sim;
  sim.with_scale = true;
  const AteResult scaled = ComputeAte(gt, est, sim);
  EXPECT_NEAR(scaled.gt_from_est.scale, 2.0, 1e-9);
  EXPECT_NEAR(scaled.error_m.rmse, 0.0, 1e-9);
  const AteResult rigid = ComputeAte(gt, est, AteOptions{});
  EXPECT_DOUBLE_EQ(rigid.gt_from_est.scale, 1.0);
  EXPECT_GT(rigid.error_m.rmse, 0.05);
}

TEST(Ate, AssociationWindowIsExclusiveAndOneToOne) {
  const Trajectory gt = MakeTrajectory(100, 10, 20, Wiggle);
  // 19 ms late: all associate.
  Trajectory est = MakeTrajectory(100.019, 10, 20, Wiggle);
  EXPECT_EQ(ComputeAte(gt, est, AteOptions{}).pairs.size(), 20u);
  // 21 ms late: none associate -> too few pairs.
  est = MakeTrajectory(100.021, 10, 20, Wiggle);
  EXPECT_THAT([&] { ComputeAte(gt, est, AteOptions{}); },
              ::testing::ThrowsMessage<InputError>(::testing::HasSubstr("at least 3")));
  // Two estimates around one gt stamp: only the closer one pairs with it.
  Trajectory dense = {{Sec(100.000), Wiggle(0)}, {Sec(100.004), Wiggle(0)},
                      {Sec(100.1), Wiggle(0.1)}, {Sec(100.2), Wiggle(0.2)}};
  const AteResult r = ComputeAte(gt, dense, AteOptions{});
  ASSERT_EQ(r.pairs.size(), 3u);
  EXPECT_EQ(r.pairs[0].est_stamp, Sec(100.000));
  EXPECT_EQ(r.pairs[1].est_stamp, Sec(100.1));
}

TEST(Ate, OffsetIsAddedToEstimateStamps) {
  const Trajectory gt = MakeTrajectory(100, 10, 20, Wiggle);
  const Trajectory est = MakeTrajectory(95, 10, 20, Wiggle);  // est clock 5 s behind
  AteOptions options;
  options.association.offset_s = 5.0;
  const AteResult r = ComputeAte(gt, est, options);
  EXPECT_EQ(r.pairs.size(), 20u);
  EXPECT_NEAR(r.error_m.rmse, 0.0, 1e-9);
  options.association.offset_s = -5.0;
  EXPECT_THROW(ComputeAte(gt, est, options), InputError);
}

TEST(Ate, ScaleAlignmentOfAStationaryEstimateIsAnInputError) {
  const Trajectory gt = MakeTrajectory(0, 10, 20, Wiggle);
  Trajectory est = gt;
  for (StampedPose& p : est) p.world_from_cam = Rigid3d();
  AteOptions sim;
  sim.with_scale = true;
  EXPECT_THROW(ComputeAte(gt, est, sim), InputError);
  // Rigid alignment of a stationary estimate is well defined: the error is the spread of gt.
  EXPECT_GT(ComputeAte(gt, est, AteOptions{}).error_m.rmse, 0.1);
}

}  // namespace
}  // namespace detslam
