#include "detslam/eval/coverage.h"

#include <gtest/gtest.h>

#include "detslam/eval/eval_test_util.h"

namespace detslam {
namespace {

using eval_test::Sec;

std::vector<Timestamp> Stamps(double t0, double rate, int n) {
  std::vector<Timestamp> out;
  for (int k = 0; k < n; ++k) out.push_back(Sec(t0 + k / rate));
  return out;
}

TEST(Coverage, DroppedFramesAreCountedExactly) {
  // 60 frames at 30 Hz, ground truth 1 ms off each; estimates miss frames 10..19 and 40.
  const std::vector<Timestamp> frames = Stamps(100, 30, 60);
  const std::vector<Timestamp> gt = Stamps(100.001, 30, 60);
  std::vector<Timestamp> est;
  for (int k = 0; k < 60; ++k) {
    if ((k >= 10 && k < 20) || k == 40) continue;
    est.push_back(frames[k]);
  }
  const CoverageResult c = ComputeCoverage(frames, gt, est, AssociationOptions{});
  EXPECT_EQ(c.frames_with_gt, 60u);
  EXPECT_EQ(c.frames_tracked, 49u);
  EXPECT_DOUBLE_EQ(c.fraction, 49.0 / 60.0);
  EXPECT_EQ(c.longest_untracked_frames, 10u);
  EXPECT_NEAR(c.longest_untracked_s, 10.0 / 30.0, 1e-9);  // 9 intervals + one frame interval
  EXPECT_EQ(c.longest_untracked_start, frames[10]);
  ASSERT_EQ(c.tracked.size(), 60u);
  EXPECT_FALSE(c.tracked[40]);
  EXPECT_TRUE(c.tracked[41]);
}

TEST(Coverage, OnlyFramesWithGroundTruthCountAndFarEstimatesDoNot) {
  const std::vector<Timestamp> frames = Stamps(0, 10, 30);  // 3 s of frames at 10 Hz
  const std::vector<Timestamp> gt = Stamps(0, 100, 96);     // gt only over 0..0.95 s
  std::vector<Timestamp> est;
  for (int k = 0; k < 30; ++k) {
    // Frames 0..4 tracked on time; estimates for 5..9 are 50 ms late, i.e. 50 ms from every
    // frame (outside 0.02 s); the rest on time.
    est.push_back(Timestamp{frames[k].ns + (k >= 5 && k < 10 ? 50'000'000 : 0)});
  }
  const CoverageResult c = ComputeCoverage(frames, gt, est, AssociationOptions{});
  EXPECT_EQ(c.frames_with_gt, 10u);  // frames 0..0.9 s; frame 1.0 s is 0.05 s from gt 0.95 s
  EXPECT_EQ(c.frames_tracked, 5u);
  EXPECT_DOUBLE_EQ(c.fraction, 0.5);
  EXPECT_EQ(c.longest_untracked_frames, 5u);
  EXPECT_NEAR(c.longest_untracked_s, 0.5, 1e-9);
  EXPECT_EQ(c.longest_untracked_start, frames[5]);
}

TEST(Coverage, NoEstimateAndNoGroundTruth) {
  const std::vector<Timestamp> frames = Stamps(0, 30, 30);
  const CoverageResult none = ComputeCoverage(frames, frames, {}, AssociationOptions{});
  EXPECT_EQ(none.frames_tracked, 0u);
  EXPECT_EQ(none.longest_untracked_frames, 30u);
  EXPECT_NEAR(none.longest_untracked_s, 1.0, 1e-9);
  const CoverageResult no_gt = ComputeCoverage(frames, {}, frames, AssociationOptions{});
  EXPECT_EQ(no_gt.frames_with_gt, 0u);
  EXPECT_EQ(no_gt.fraction, 0.0);
}

}  // namespace
}  // namespace detslam
