#include "detslam/dynamic/mask_propagation.h"

#include <thread>

#include "detslam/dynamic/mask_carrier.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "detslam/core/check.h"

namespace detslam {
namespace {

// A textured square (the "person") at `corner` over a differently textured background.
cv::Mat SquareImage(cv::Point corner) {
  cv::Mat img(240, 320, CV_8UC1);
  cv::RNG bg(1), fg(2);
  bg.fill(img, cv::RNG::UNIFORM, 0, 100);
  cv::GaussianBlur(img, img, cv::Size(3, 3), 0);
  cv::Mat patch(60, 60, CV_8UC1);
  fg.fill(patch, cv::RNG::UNIFORM, 100, 255);
  cv::GaussianBlur(patch, patch, cv::Size(3, 3), 0);
  patch.copyTo(img(cv::Rect(corner, patch.size())));
  return img;
}

Instance Square(cv::Point corner) {
  Instance inst;
  inst.class_name = "person";
  inst.box = cv::Rect(corner, cv::Size(60, 60));
  inst.mask = cv::Mat::zeros(240, 320, CV_8UC1);
  inst.mask(inst.box).setTo(255);
  return inst;
}

cv::Point2d Centroid(const cv::Mat& mask) {
  const cv::Moments m = cv::moments(mask, true);
  return {m.m10 / m.m00, m.m01 / m.m00};
}

TEST(MaskPropagation, EmptyBeforeTheFirstSegmentedFrame) {
  MaskPropagator p;
  EXPECT_TRUE(p.Propagate(SquareImage({50, 50})).empty());
}

TEST(MaskPropagation, MasksFollowTheMovingObjectAndGrowWithAge) {
  MaskPropagationOptions o;
  o.grow_px_per_frame = 2;
  MaskPropagator p(o);
  p.Reset(SquareImage({100, 80}), {Square({100, 80})});
  std::vector<Instance> out = p.Propagate(SquareImage({106, 83}));
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(p.age(), 1);
  cv::Point2d c = Centroid(out[0].mask);
  EXPECT_NEAR(c.x, 136, 1.0);
  EXPECT_NEAR(c.y, 113, 1.0);
  // Grown by 2 px on each side: a 64 x 64 footprint (rounded corners of the ellipse kernel).
  EXPECT_NEAR(cv::countNonZero(out[0].mask), 64 * 64, 40);
  EXPECT_EQ(out[0].box, cv::Rect(104, 81, 64, 64));
  // Second frame: follows again, from the previous (propagated) frame, grown by 4 px.
  out = p.Propagate(SquareImage({112, 86}));
  ASSERT_EQ(out.size(), 1u);
  c = Centroid(out[0].mask);
  EXPECT_NEAR(c.x, 142, 1.0);
  EXPECT_NEAR(c.y, 116, 1.0);
  EXPECT_EQ(out[0].box, cv::Rect(108, 82, 68, 68));
  // A new segmentation resets the age.
  p.Reset(SquareImage({112, 86}), {Square({112, 86})});
  EXPECT_EQ(p.age(), 0);
}

TEST(MaskPropagation, AJumpOverSeveralFramesGrowsTheMaskByTheirNumber) {
  MaskPropagationOptions o;
  o.grow_px_per_frame = 2;
  MaskPropagator p(o);
  p.Reset(SquareImage({100, 80}), {Square({100, 80})});
  // Three input frames later (two dropped in between): moved by the whole motion, grown by 6 px.
  const std::vector<Instance> out = p.Propagate(SquareImage({112, 86}), 3);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(p.age(), 3);
  const cv::Point2d c = Centroid(out[0].mask);
  EXPECT_NEAR(c.x, 142, 1.0);
  EXPECT_NEAR(c.y, 116, 1.0);
  EXPECT_EQ(out[0].box, cv::Rect(106, 80, 72, 72));
  EXPECT_DEATH(p.Propagate(SquareImage({112, 86}), 0), "");
}

// The flow on reduced images: the same motion found, within a pixel, at every scale; a box whose
// corner is not on the reduced grid (odd coordinates) too.
class ReducedFlow : public ::testing::TestWithParam<int> {};

TEST_P(ReducedFlow, FollowsTheObjectAsAtFullResolution) {
  MaskPropagationOptions o;
  o.grow_px_per_frame = 0;
  o.flow_scale = GetParam();
  MaskPropagator p(o);
  p.Reset(SquareImage({101, 81}), {Square({101, 81})});
  std::vector<Instance> out = p.Propagate(SquareImage({108, 84}));
  ASSERT_EQ(out.size(), 1u);
  cv::Point2d c = Centroid(out[0].mask);
  EXPECT_NEAR(c.x, 138.5, 1.0);
  EXPECT_NEAR(c.y, 113.5, 1.0);
  // A larger step over three frames, then back: the mask ends where the object is.
  out = p.Propagate(SquareImage({125, 70}), 3);
  ASSERT_EQ(out.size(), 1u);
  c = Centroid(out[0].mask);
  EXPECT_NEAR(c.x, 154.5, 1.0);
  EXPECT_NEAR(c.y, 99.5, 1.0);
  EXPECT_NEAR(out[0].box.x, 125, 1);
  EXPECT_NEAR(out[0].box.y, 70, 1);
  EXPECT_EQ(out[0].box.size(), cv::Size(60, 60));
}

INSTANTIATE_TEST_SUITE_P(MaskPropagation, ReducedFlow, ::testing::Values(1, 2, 4));

TEST(MaskCarrier, NothingBeforeTheFirstPublishedSegmentation) {
  MaskCarrier carrier;
  EXPECT_FALSE(carrier.Carry(0, SquareImage({50, 50})).has_value());
  EXPECT_EQ(carrier.published(), 0);
}

TEST(MaskCarrier, CarriesTheNewestSegmentationToLaterFramesWithItsAge) {
  MaskPropagationOptions o;
  o.grow_px_per_frame = 2;
  MaskCarrier carrier(o);
  // The object moves 3 px right per input frame.
  const auto image = [](int frame) { return SquareImage({100 + 3 * frame, 80}); };
  const auto square = [](int frame) { return Square({100 + 3 * frame, 80}); };
  carrier.Publish(0, image(0), {square(0)});
  std::optional<CarriedInstances> c = carrier.Carry(0, image(0));  // its own segmentation
  ASSERT_TRUE(c.has_value());
  EXPECT_EQ(c->source, 0);
  EXPECT_EQ(c->age, 0);
  ASSERT_EQ(c->instances.size(), 1u);
  EXPECT_EQ(c->instances[0].box, cv::Rect(100, 80, 60, 60));
  // Frames 1 and 3 (2 dropped): carried by the flow, age counted in input frames.
  c = carrier.Carry(1, image(1));
  ASSERT_TRUE(c.has_value());
  EXPECT_EQ(c->age, 1);
  EXPECT_NEAR(Centroid(c->instances[0].mask).x, 133, 1.0);
  c = carrier.Carry(3, image(3));
  ASSERT_TRUE(c.has_value());
  EXPECT_EQ(c->age, 3);
  EXPECT_NEAR(Centroid(c->instances[0].mask).x, 139, 1.0);
  EXPECT_EQ(c->instances[0].box, cv::Rect(109 - 6, 80 - 6, 72, 72));
  // The segmentation of frame 2 arrives while frame 4 is carried: it replaces the older one, is
  // carried from frame 2's image, and its age is 2.
  carrier.Publish(2, image(2), {square(2)});
  c = carrier.Carry(4, image(4));
  ASSERT_TRUE(c.has_value());
  EXPECT_EQ(c->source, 2);
  EXPECT_EQ(c->age, 2);
  EXPECT_NEAR(Centroid(c->instances[0].mask).x, 142, 1.0);
  EXPECT_EQ(c->instances[0].box, cv::Rect(112 - 4, 80 - 4, 68, 68));
  // A result older than the newest published one is ignored; one of a frame not carried yet
  // waits for it.
  carrier.Publish(1, image(1), {});
  carrier.Publish(6, image(6), {});
  c = carrier.Carry(5, image(5));
  ASSERT_TRUE(c.has_value());
  EXPECT_EQ(c->source, 2);
  EXPECT_EQ(c->instances.size(), 1u);
  c = carrier.Carry(6, image(6));
  ASSERT_TRUE(c.has_value());
  EXPECT_EQ(c->source, 6);
  EXPECT_TRUE(c->instances.empty());
  EXPECT_EQ(carrier.published(), 3);
  EXPECT_DEATH(carrier.Carry(6, image(6)), "");  // frames out of input order
}

TEST(MaskCarrier, WaitForReturnsWhenPublishedOrClosed) {
  MaskCarrier carrier;
  std::thread segmentation([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    carrier.Publish(3, SquareImage({50, 50}), {});
  });
  EXPECT_TRUE(carrier.WaitFor(3));
  segmentation.join();
  EXPECT_TRUE(carrier.WaitFor(2));  // a later frame's masks do
  std::thread closer([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    carrier.Close();
  });
  EXPECT_FALSE(carrier.WaitFor(10));
  closer.join();
}

TEST(MaskPropagation, ShiftMaskMovesPixelsAndClearsTheBorder) {
  cv::Mat m = cv::Mat::zeros(10, 10, CV_8UC1);
  m.at<uint8_t>(2, 3) = 255;
  const cv::Mat s = ShiftMask(m, 2, 1);
  EXPECT_EQ(s.at<uint8_t>(3, 5), 255);
  EXPECT_EQ(cv::countNonZero(s), 1);
  EXPECT_EQ(cv::countNonZero(ShiftMask(m, 20, 0)), 0);
}

// The whole-pixel copy equals the translation by cv::warpAffine(INTER_NEAREST) it replaced, for
// fractional shifts (halves included), shifts off the image and a non-binary mask.
TEST(MaskPropagation, ShiftMaskEqualsWarpAffineNearest) {
  cv::Mat m(48, 64, CV_8UC1);
  cv::RNG(5).fill(m, cv::RNG::UNIFORM, 0, 256);
  cv::RNG rng(11);
  std::vector<double> shifts = {0, 0.5, -0.5, 1.5, -1.5, 2.4999, -2.5001, 63.6, -70, 12.49951};
  for (int i = 0; i < 40; ++i) shifts.push_back(rng.uniform(-30.0, 30.0));
  for (double dx : shifts) {
    for (double dy : {0.5, -3.7, 0.0, 10.25, -0.5}) {
      cv::Mat reference;
      const cv::Mat t = (cv::Mat_<double>(2, 3) << 1, 0, dx, 0, 1, dy);
      cv::warpAffine(m, reference, t, m.size(), cv::INTER_NEAREST, cv::BORDER_CONSTANT, 0);
      EXPECT_EQ(cv::norm(ShiftMask(m, dx, dy), reference, cv::NORM_INF), 0.0)
          << "dx " << dx << " dy " << dy;
    }
  }
  EXPECT_EQ(NearestShift(0.5), 0);
  EXPECT_EQ(NearestShift(-0.5), -1);
  EXPECT_EQ(NearestShift(2.6), 3);
}

TEST(MaskPropagation, RejectsInvalidOptions) {
  MaskPropagationOptions o;
  o.max_corners = 0;
  std::string error;
  EXPECT_FALSE(o.Check(&error));
  EXPECT_NE(error.find("max_corners"), std::string::npos);
  EXPECT_DEATH(MaskPropagator{o}, "");
  o = MaskPropagationOptions();
  o.flow_scale = 3;
  EXPECT_FALSE(o.Check(&error));
  EXPECT_NE(error.find("flow_scale"), std::string::npos);
}

}  // namespace
}  // namespace detslam
