#include "detslam/dynamic/instance_memory.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace detslam {
namespace {

Instance Person(int x) {
  Instance i;
  i.class_name = "person";
  i.box = cv::Rect(x, 10, 50, 100);
  return i;
}

TEST(InstanceMemory, CarriesALostInstanceForAtMostMaxAgeFrames) {
  InstanceMemory memory(2);
  EXPECT_EQ(memory.Update({Person(0), Person(300)}).size(), 2u);
  // The person at x=300 is missed: it is carried for two frames, then dropped.
  std::vector<Instance> f1 = memory.Update({Person(2)});
  ASSERT_EQ(f1.size(), 2u);
  EXPECT_EQ(f1[1].box.x, 300);
  EXPECT_EQ(memory.Update({Person(4)}).size(), 2u);
  EXPECT_EQ(memory.Update({Person(6)}).size(), 1u);
}

TEST(InstanceMemory, OverlappingDetectionReplacesTheRememberedOne) {
  InstanceMemory memory(3);
  memory.Update({Person(100)});
  const std::vector<Instance> out = memory.Update({Person(105)});
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].box.x, 105);
}

TEST(InstanceMemory, ZeroAgeIsPassThrough) {
  InstanceMemory memory(0);
  memory.Update({Person(0)});
  EXPECT_TRUE(memory.Update({}).empty());
}

// A 640x480 depth image: background at 3 m, a person-sized block at 1.2 m with its left edge at x.
cv::Mat DepthWithPerson(int x) {
  cv::Mat depth(480, 640, CV_32FC1, cv::Scalar(3.0f));
  depth(cv::Rect(x, 100, 120, 300) & cv::Rect(0, 0, 640, 480)).setTo(1.2f);
  return depth;
}

Instance PersonWithMask(int x) {
  Instance i;
  i.class_name = "person";
  i.box = cv::Rect(x, 100, 120, 300) & cv::Rect(0, 0, 640, 480);
  i.mask = cv::Mat(480, 640, CV_8UC1, cv::Scalar(0));
  i.mask(i.box).setTo(255);
  return i;
}

TEST(DepthTrack, FollowsTheMaskIntoTheNewDepth) {
  Instance followed;
  ASSERT_TRUE(DepthTrack::Follow(PersonWithMask(300), DepthWithPerson(320), &followed));
  EXPECT_EQ(followed.box, cv::Rect(320, 100, 120, 300));
  EXPECT_EQ(cv::countNonZero(followed.mask), 120 * 300);
  EXPECT_EQ(followed.mask.at<uint8_t>(250, 430), 255);  // moved-into pixel
  EXPECT_EQ(followed.mask.at<uint8_t>(250, 305), 0);    // left behind
  EXPECT_EQ(followed.class_name, "person");
}

TEST(DepthTrack, StopsWhenThePersonIsGoneOrHasNoDepth) {
  Instance followed;
  const cv::Mat background(480, 640, CV_32FC1, cv::Scalar(3.0f));
  EXPECT_FALSE(DepthTrack::Follow(PersonWithMask(300), background, &followed));
  // Mostly out of the view: less than half of the previous area is left.
  EXPECT_FALSE(DepthTrack::Follow(PersonWithMask(300), DepthWithPerson(620), &followed));
  EXPECT_FALSE(DepthTrack::Follow(PersonWithMask(300), cv::Mat(480, 640, CV_32FC1, cv::Scalar(0.0f)),
                                  &followed));
  EXPECT_FALSE(DepthTrack::Follow(PersonWithMask(300), cv::Mat(), &followed));
  EXPECT_FALSE(DepthTrack::Follow(Person(300), DepthWithPerson(300), &followed));  // no mask
}

TEST(DepthTrack, StopsWhenTheRegionMergesWithTheBackground) {
  // The background comes to the person's depth (e.g. a wall right behind): the region grows far
  // beyond the mask, which is refused rather than masking the wall.
  Instance followed;
  EXPECT_FALSE(DepthTrack::Follow(PersonWithMask(300), cv::Mat(480, 640, CV_32FC1, cv::Scalar(1.2f)),
                                  &followed));
}

TEST(InstanceMemory, FollowsALostPersonInDepthForAtMostDepthTrackAgeFrames) {
  InstanceMemory memory(1, 0.3, 4);
  memory.Update({PersonWithMask(100)}, DepthWithPerson(100));
  for (int age = 1; age <= 4; ++age) {
    const std::vector<Instance> out = memory.Update({}, DepthWithPerson(100 + 10 * age));
    ASSERT_EQ(out.size(), 1u) << "age " << age;
    EXPECT_EQ(out[0].box.x, 100 + 10 * age) << "age " << age;
  }
  EXPECT_TRUE(memory.Update({}, DepthWithPerson(150)).empty());
}

// With the segmenter on every k-th frame only, depth tracking still ends after depth_track_age
// frames (not calls).
TEST(InstanceMemory, DepthTrackAgeCountsFrames) {
  InstanceMemory memory(0, 0.3, 6);
  memory.Update({PersonWithMask(100)}, DepthWithPerson(100), 3);
  EXPECT_EQ(memory.Update({}, DepthWithPerson(105), 3).size(), 1u);  // 3 frames
  EXPECT_EQ(memory.Update({}, DepthWithPerson(110), 3).size(), 1u);  // 6 frames
  EXPECT_TRUE(memory.Update({}, DepthWithPerson(115), 3).empty());   // 9 frames
}

TEST(InstanceMemory, FallsBackToThePlainCarryWhenDepthCannotFollow) {
  InstanceMemory memory(2, 0.3, 10);
  memory.Update({PersonWithMask(100)}, DepthWithPerson(100));
  const cv::Mat background(480, 640, CV_32FC1, cv::Scalar(3.0f));
  for (int age = 1; age <= 2; ++age) {
    const std::vector<Instance> out = memory.Update({}, background);
    ASSERT_EQ(out.size(), 1u) << "age " << age;
    EXPECT_EQ(out[0].box.x, 100);  // unchanged
  }
  EXPECT_TRUE(memory.Update({}, background).empty());
}

TEST(InstanceMemory, ADetectionEndsTheDepthTracking) {
  InstanceMemory memory(0, 0.3, 10);
  memory.Update({PersonWithMask(100)}, DepthWithPerson(100));
  memory.Update({}, DepthWithPerson(110));
  const std::vector<Instance> out = memory.Update({PersonWithMask(125)}, DepthWithPerson(125));
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].box.x, 125);
}

}  // namespace
}  // namespace detslam
