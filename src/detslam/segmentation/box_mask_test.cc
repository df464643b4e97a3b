#include "detslam/segmentation/box_mask.h"

#include <gtest/gtest.h>

namespace detslam {
namespace {

// 120x100 depth image: background wall at 3 m, a person-like slab at 1.5 m (+-0.1 m ramp) in
// columns 25..54, rows 20..79, with a few holes (no depth) inside it.
struct Scene {
  cv::Mat depth{100, 120, CV_32FC1, cv::Scalar(3.0f)};
  cv::Mat truth{100, 120, CV_8UC1, cv::Scalar(0)};  // slab pixels with valid depth
  Scene() {
    for (int y = 20; y < 80; ++y) {
      for (int x = 25; x < 55; ++x) {
        if ((x * 7 + y * 3) % 23 == 0) {
          depth.at<float>(y, x) = 0.0f;
          continue;
        }
        depth.at<float>(y, x) = 1.4f + 0.2f * (x - 25) / 29.0f;
        truth.at<uint8_t>(y, x) = 255;
      }
    }
  }
};

TEST(BoxMask, ExpandBoxGrowsEachSideAndClips) {
  EXPECT_EQ(ExpandBox(cv::Rect(20, 30, 100, 50), 0.1, cv::Size(640, 480)),
            cv::Rect(10, 25, 120, 60));
  EXPECT_EQ(ExpandBox(cv::Rect(0, 0, 100, 50), 0.1, cv::Size(105, 480)), cv::Rect(0, 0, 105, 55));
}

TEST(BoxMask, KeepsTheDominantDepthInsideTheBoxOnly) {
  Scene s;
  const cv::Rect box(20, 15, 40, 70);  // slab 30x60 = 1800 px, wall 1000 px
  const cv::Mat mask = DominantDepthBoxMask(s.depth, box, s.depth.size(), DominantDepthOptions());
  ASSERT_EQ(mask.type(), CV_8UC1);
  EXPECT_EQ(cv::countNonZero(mask != s.truth), 0) << "mask must be exactly the valid slab pixels";
  // Nothing outside the box, even though the wall outside has the same depth as inside.
  cv::Mat outside = mask.clone();
  outside(box).setTo(0);
  EXPECT_EQ(cv::countNonZero(outside), 0);
}

TEST(BoxMask, WallDominatesAWideBox) {
  Scene s;
  const cv::Rect box(0, 0, 120, 100);  // wall 10200 px > slab 1800 px
  const cv::Mat mask = DominantDepthBoxMask(s.depth, box, s.depth.size(), DominantDepthOptions());
  EXPECT_EQ(cv::countNonZero(mask & s.truth), 0);
  EXPECT_EQ(cv::countNonZero(mask), 120 * 100 - 60 * 30);
}

TEST(BoxMask, ToleranceControlsTheDepthWindow) {
  Scene s;
  DominantDepthOptions narrow;
  narrow.tolerance_m = 0.02;
  const cv::Mat mask =
      DominantDepthBoxMask(s.depth, cv::Rect(20, 15, 40, 70), s.depth.size(), narrow);
  const int n = cv::countNonZero(mask);
  EXPECT_GT(n, 0);
  EXPECT_LT(n, cv::countNonZero(s.truth) / 2);  // only part of the 0.2 m ramp
  EXPECT_EQ(cv::countNonZero(mask & ~s.truth), 0);
}

TEST(BoxMask, WholeBoxWithoutDepthOrWithTooFewDepths) {
  const cv::Size size(120, 100);
  const cv::Rect box(100, 90, 50, 50);  // clipped to 20x10
  cv::Mat m = DominantDepthBoxMask(cv::Mat(), box, size, DominantDepthOptions());
  EXPECT_EQ(cv::countNonZero(m), 20 * 10);
  EXPECT_EQ(cv::countNonZero(m(cv::Rect(100, 90, 20, 10))), 200);
  cv::Mat sparse(size, CV_32FC1, cv::Scalar(0.0f));
  for (int i = 0; i < 5; ++i) sparse.at<float>(92, 101 + i) = 2.0f;
  m = DominantDepthBoxMask(sparse, box, size, DominantDepthOptions());
  EXPECT_EQ(cv::countNonZero(m), 200);
}

TEST(BoxMask, OptionsCheck) {
  DominantDepthOptions o;
  std::string error;
  EXPECT_TRUE(o.Check(&error));
  o.bin_m = 0;
  EXPECT_FALSE(o.Check(&error));
  EXPECT_NE(error.find("bin"), std::string::npos);
}

TEST(BoxMask, PersonMaskFallsBackToDepthWhenTheModelMaskIsTooSmall) {
  Scene s;
  const cv::Rect box(20, 15, 40, 70);  // 2800 px
  const cv::Mat depth_mask = DominantDepthBoxMask(s.depth, box, s.depth.size(), DominantDepthOptions());
  // A model mask covering 30x40 = 1200 px (43 % of the box) is kept as it is.
  cv::Mat model(s.depth.size(), CV_8UC1, cv::Scalar(0));
  model(cv::Rect(25, 30, 30, 40)).setTo(255);
  cv::Mat kept = PersonMaskOrDepth(model, box, 0.25, s.depth, DominantDepthOptions());
  EXPECT_EQ(cv::countNonZero(kept != model), 0);
  // A model mask covering 10x10 = 100 px (4 %) gives way to the dominant-depth mask.
  model.setTo(0);
  model(cv::Rect(30, 30, 10, 10)).setTo(255);
  cv::Mat replaced = PersonMaskOrDepth(model, box, 0.25, s.depth, DominantDepthOptions());
  EXPECT_EQ(cv::countNonZero(replaced != depth_mask), 0);
  // min_fill 0 keeps even an empty model mask.
  model.setTo(0);
  EXPECT_EQ(cv::countNonZero(PersonMaskOrDepth(model, box, 0.0, s.depth, DominantDepthOptions())), 0);
}

TEST(BoxMask, IouOfMasksAndBoxes) {
  cv::Mat a(10, 10, CV_8UC1, cv::Scalar(0)), b = a.clone();
  a(cv::Rect(0, 0, 4, 5)).setTo(1);
  b(cv::Rect(2, 0, 4, 5)).setTo(255);
  EXPECT_DOUBLE_EQ(MaskIou(a, b), 10.0 / 30.0);
  EXPECT_DOUBLE_EQ(MaskIou(cv::Mat(a.size(), CV_8UC1, cv::Scalar(0)), a * 0), 0.0);
  EXPECT_DOUBLE_EQ(BoxIou(cv::Rect(0, 0, 4, 5), cv::Rect(2, 0, 4, 5)), 10.0 / 30.0);
}

}  // namespace
}  // namespace detslam
