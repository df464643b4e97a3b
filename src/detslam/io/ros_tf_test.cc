#include "detslam/io/ros_tf.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "detslam/core/check.h"
#include "support/bag_writer.h"
#include "support/cli_runner.h"

namespace detslam {
namespace ros_tf_test {
namespace {
using ::testing::HasSubstr;

Timestamp Stamp(double s) { return Timestamp::FromSeconds(s); }

RosTransform Tf(const std::string& parent, const std::string& child, double t,
                const Eigen::Vector3d& p, const Eigen::Quaterniond& q) {
  RosTransform x;
  x.header.frame_id = parent;
  x.header.stamp = Stamp(t);
  x.child_frame_id = child;
  x.translation = {p.x(), p.y(), p.z()};
  x.rotation = {q.x(), q.y(), q.z(), q.w()};
  return x;
}

Eigen::Quaterniond Yaw(double deg) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(deg * M_PI / 180, Eigen::Vector3d::UnitZ()));
}

TEST(TfBuffer, ComposesChainsAndInterpolatesMovingEdges) {
  TfBuffer tf;
  // world -> body moves along x (1 m/s) and turns (90 deg/s); body -> camera is fixed.
  for (int i = 0; i <= 10; ++i) {
    tf.Add(Tf("/world", "/body", 0.1 * i, Eigen::Vector3d(0.1 * i, 0, 0), Yaw(9.0 * i)));
  }
  tf.Add(Tf("body", "camera", 0, Eigen::Vector3d(0, 0.5, 0), Eigen::Quaterniond::Identity()));
  tf.Add(Tf("world", "landmark", 0, Eigen::Vector3d(3, 0, 0), Eigen::Quaterniond::Identity()));
  tf.Finish();
  // At a sample: world_from_camera = world_from_body * body_from_camera.
  const std::optional<Rigid3d> at = tf.Lookup("world", "/camera", Stamp(1.0));
  ASSERT_TRUE(at);
  EXPECT_NEAR(at->translation().x(), 1.0 - 0.5, 1e-12);  // body turned 90 deg: +y maps to -x
  EXPECT_NEAR(at->translation().y(), 0.0, 1e-12);
  // Between samples: half-way in translation and angle.
  const std::optional<Rigid3d> mid = tf.Lookup("world", "body", Stamp(0.55));
  ASSERT_TRUE(mid);
  EXPECT_NEAR(mid->translation().x(), 0.55, 1e-12);
  EXPECT_NEAR(mid->rotation().angularDistance(Yaw(49.5)), 0, 1e-9);
  // Across the tree (camera in landmark's frame): landmark_from_world * world_from_camera.
  const std::optional<Rigid3d> rel = tf.Lookup("landmark", "camera", Stamp(1.0));
  ASSERT_TRUE(rel);
  EXPECT_NEAR(rel->translation().x(), 0.5 - 3.0, 1e-12);
  // Outside the moving edge's span, or unknown frames: no pose.
  EXPECT_FALSE(tf.Lookup("world", "camera", Stamp(1.5)));
  EXPECT_FALSE(tf.Lookup("world", "nowhere", Stamp(0.5)));
  // The chain moves at the body edge's stamps; the landmark's fixed edge never moves.
  EXPECT_EQ(tf.ChainStamps("world", "camera").size(), 11u);
  EXPECT_TRUE(tf.ChainStamps("world", "landmark").empty());
  EXPECT_EQ(tf.Frames(), (std::vector<std::string>{"body", "camera", "landmark", "world"}));
}

TEST(TfBuffer, IgnoresSecondParentsLoopsAndBadValues) {
  TfBuffer tf;
  tf.Add(Tf("a", "b", 0, Eigen::Vector3d::Zero(), Eigen::Quaterniond::Identity()));
  tf.Add(Tf("c", "b", 0, Eigen::Vector3d::Zero(), Eigen::Quaterniond::Identity()));  // 2nd parent
  tf.Add(Tf("b", "a", 0, Eigen::Vector3d::Zero(), Eigen::Quaterniond::Identity()));  // a cycle
  tf.Add(Tf("a", "a", 0, Eigen::Vector3d::Zero(), Eigen::Quaterniond::Identity()));  // self
  RosTransform nan = Tf("a", "d", 0, Eigen::Vector3d::Zero(), Eigen::Quaterniond::Identity());
  nan.translation[0] = std::nan("");
  tf.Add(nan);
  RosTransform zero = Tf("a", "e", 0, Eigen::Vector3d::Zero(), Eigen::Quaterniond::Identity());
  zero.rotation = {0, 0, 0, 0};
  tf.Add(zero);
  tf.Finish();
  EXPECT_EQ(tf.ignored(), 4u);
  EXPECT_TRUE(tf.Lookup("a", "b", Stamp(0)));  // the cycle a <-> b ends the walk, no hang
  EXPECT_FALSE(tf.Has("d"));
}

// A bag like TUM's: /tf with world -> kinect at 100 Hz, /tf_static kinect -> optical frame.
std::vector<uint8_t> TfBag() {
  testing::BagWriter w(RosbagCompression::kNone, 2000);
  const uint32_t tf = w.AddConnection("/tf", "tf2_msgs/TFMessage");
  const uint32_t stat = w.AddConnection("/tf_static", "tf2_msgs/TFMessage");
  const uint32_t rgb = w.AddConnection("/camera/rgb/image_color", "sensor_msgs/Image");
  const auto tf_message = [](const std::string& parent, const std::string& child, Timestamp t,
                             const Eigen::Vector3d& p, const Eigen::Quaterniond& q) {
    testing::Bytes m;
    m.U32(1).U32(0).Time(t).String(parent).String(child);
    m.F64(p.x()).F64(p.y()).F64(p.z()).F64(q.x()).F64(q.y()).F64(q.z()).F64(q.w());
    return m.bytes();
  };
  w.Write(stat, Stamp(1), tf_message("/kinect", "/openni_rgb_optical_frame", Stamp(1),
                                     Eigen::Vector3d(0, 0.02, 0), Yaw(-90)));
  for (int i = 0; i < 100; ++i) {
    const Timestamp t = Stamp(1 + 0.01 * i);
    w.Write(tf, t, tf_message("/world", "/kinect", t, Eigen::Vector3d(0.01 * i, 0, 1), Yaw(i)));
  }
  cv::Mat im(2, 2, CV_8UC3, cv::Scalar(0));
  w.Write(rgb, Stamp(1.5), testing::ImageMessage(Stamp(1.5), im, "rgb8"));
  std::vector<uint8_t> bytes = w.Finish();
  return bytes;
}

TEST(GroundTruthFromBag, TumStyleTree) {
  const std::string path = testing::WriteBagFile(TfBag(), "tf.bag");
  TfGroundTruthOptions o;
  o.child = "/openni_rgb_optical_frame";
  const TfGroundTruth gt = GroundTruthFromBag(path, o);
  EXPECT_EQ(gt.parent, "world");
  EXPECT_EQ(gt.transforms, 101u);
  ASSERT_EQ(gt.trajectory.size(), 100u);
  const Rigid3d expected = Rigid3d(Yaw(50), Eigen::Vector3d(0.5, 0, 1)) *
                           Rigid3d(Yaw(-90), Eigen::Vector3d(0, 0.02, 0));
  EXPECT_EQ(gt.trajectory[50].stamp, Stamp(1.5));
  EXPECT_LT((gt.trajectory[50].world_from_cam.translation() - expected.translation()).norm(), 1e-12);
  EXPECT_LT(gt.trajectory[50].world_from_cam.rotation().angularDistance(expected.rotation()), 1e-9);
  // The image's frame_id ("camera", from the test writer) is the default child: not in the tree.
  try {
    GroundTruthFromBag(path, TfGroundTruthOptions());
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("frame 'camera' is not in the tf tree (frames: kinect, "
                                    "openni_rgb_optical_frame, world)"));
  }
  o.tf_topics = {"/tf_static"};
  EXPECT_THROW(GroundTruthFromBag(path, o), InputError);  // no moving transform
  o.tf_topics = {"/nope"};
  EXPECT_THROW(GroundTruthFromBag(path, o), InputError);  // no tf at all
}

}  // namespace
}  // namespace ros_tf_test
}  // namespace detslam
