#include "detslam/pipeline/keyframe_mask_recorder.h"

#include <gtest/gtest.h>

namespace detslam {
namespace {

const cv::Size kSize(64, 48);

std::vector<Instance> PersonAt(const cv::Rect& box) {
  Instance i;
  i.class_name = "person";
  i.score = 0.9f;
  i.box = box;
  i.mask = cv::Mat(kSize, CV_8UC1, cv::Scalar(0));
  i.mask(box).setTo(255);
  return {i};
}

cv::Mat Depth() { return cv::Mat(kSize, CV_32FC1, cv::Scalar(2.0f)); }

DynamicFilterOptions NoDilation() {
  DynamicFilterOptions o;
  o.mask_dilation_px = 0;
  o.depth_step = false;
  return o;
}

TEST(KeyframeMaskRecorder, AKeyframeTakesThePeopleFoundInItsNextFrames) {
  KeyframeMaskRecorder recorder(NoDilation(), /*lookahead=*/3);
  recorder.AddFrame(0, true, {}, Depth());                             // missed at the keyframe
  recorder.AddFrame(1, false, PersonAt(cv::Rect(0, 0, 10, 48)), Depth());  // found a frame later
  recorder.AddFrame(2, false, {}, Depth());
  recorder.AddFrame(3, false, {}, Depth());
  recorder.AddFrame(4, false, PersonAt(cv::Rect(50, 0, 10, 48)), Depth());  // beyond 3 frames
  recorder.AddFrame(10, true, {}, Depth());  // no person near this keyframe: no mask
  recorder.AddFrame(11, false, {}, Depth());
  recorder.AddFrame(20, true, PersonAt(cv::Rect(20, 10, 5, 5)), Depth());  // still waiting at the end
  const KeyframeMasks masks = recorder.Finish();
  ASSERT_EQ(masks.size(), 2u);
  const cv::Mat m0 = DecodeKeyframeMask(masks.at(0));
  ASSERT_EQ(m0.size(), kSize);
  EXPECT_EQ(cv::countNonZero(m0), 10 * 48);
  EXPECT_EQ(m0.at<uint8_t>(5, 5), 255);
  EXPECT_EQ(m0.at<uint8_t>(5, 55), 0);
  EXPECT_EQ(cv::countNonZero(DecodeKeyframeMask(masks.at(20))), 25);
  EXPECT_EQ(masks.count(10), 0u);
}

TEST(KeyframeMaskRecorder, WithoutLookaheadOnlyTheKeyframesOwnPeopleCount) {
  KeyframeMaskRecorder recorder(NoDilation(), 0);
  recorder.AddFrame(0, true, {}, Depth());
  recorder.AddFrame(1, false, PersonAt(cv::Rect(0, 0, 10, 48)), Depth());
  recorder.AddFrame(2, true, PersonAt(cv::Rect(0, 0, 4, 4)), Depth());
  const KeyframeMasks masks = recorder.Finish();
  ASSERT_EQ(masks.size(), 1u);
  EXPECT_EQ(cv::countNonZero(DecodeKeyframeMask(masks.at(2))), 16);
}

}  // namespace
}  // namespace detslam
