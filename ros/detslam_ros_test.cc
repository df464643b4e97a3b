// The ROS 1 node end to end: the test starts a ROS master and detslam_ros, publishes a synthetic
// sequence with people (colour, depth, camera info) frame by frame, and checks what the node
// publishes (poses, dynamic masks, map points) and saves (its trajectory equals the library's
// sequential run on the same frames).
#include <geometry_msgs/PoseStamped.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_srvs/Trigger.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <thread>

#include "detslam/eval/evaluate.h"
#include "detslam/io/dataset.h"
#include "detslam/io/rosbag_source.h"
#include "detslam/io/settings.h"
#include "detslam/io/trajectory.h"
#include "detslam/pipeline/runner.h"
#include "detslam/pipeline/settings_keys.h"
#include "detslam/segmentation/segmenter_factory.h"
#include "detslam/synth/writer.h"
#include "integration_util.h"
#include "support/cli_runner.h"
#include "support/ros_test_bag.h"

namespace detslam {
namespace {
namespace fs = std::filesystem;
using namespace std::chrono_literals;
using testing::ImageMsg;

constexpr int kFrames = 40;

// Spins until `done` holds or `timeout` passes.
template <typename F>
bool SpinUntil(F&& done, std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (!done()) {
    if (std::chrono::steady_clock::now() > end || !ros::ok()) return false;
    ros::spinOnce();
    std::this_thread::sleep_for(5ms);
  }
  return true;
}

std::string PosesOf(const std::string& trajectory) {
  std::ifstream in(trajectory);
  std::string line, out;
  while (std::getline(in, line)) {
    if (!line.empty() && line[0] != '#') out += line + "\n";
  }
  return out;
}

// What the node publishes, as a test subscriber sees it.
struct NodeOutputs {
  // `node`: the node's name (its private topics' namespace).
  NodeOutputs(ros::NodeHandle& nh, const std::string& node) {
    pose = nh.subscribe<geometry_msgs::PoseStamped>(
        node + "/pose", 100, [this](const geometry_msgs::PoseStampedConstPtr& p) { poses.push_back(*p); });
    mask = nh.subscribe<sensor_msgs::Image>(node + "/dynamic_mask", 100,
                                            [this](const sensor_msgs::ImageConstPtr& m) {
                                              ++masks;
                                              if (std::any_of(m->data.begin(), m->data.end(),
                                                              [](uint8_t v) { return v != 0; }))
                                                ++masks_with_objects;
                                            });
    points = nh.subscribe<sensor_msgs::PointCloud2>(
        node + "/map_points", 10,
        [this](const sensor_msgs::PointCloud2ConstPtr& c) { most_points = std::max<size_t>(most_points, c->width); });
  }
  bool Connected() const {
    return pose.getNumPublishers() > 0 && mask.getNumPublishers() > 0 && points.getNumPublishers() > 0;
  }
  Trajectory Published() const {
    Trajectory out;
    for (const auto& p : poses) {
      const auto& q = p.pose.orientation;
      out.push_back({Timestamp{static_cast<int64_t>(p.header.stamp.sec) * 1000000000 + p.header.stamp.nsec},
                     Rigid3d(Eigen::Quaterniond(q.w, q.x, q.y, q.z),
                             Eigen::Vector3d(p.pose.position.x, p.pose.position.y, p.pose.position.z))});
    }
    return out;
  }
  std::vector<geometry_msgs::PoseStamped> poses;
  int masks = 0, masks_with_objects = 0;
  size_t most_points = 0;
  ros::Subscriber pose, mask, points;
};

// The library's sequential run on the folder (the node's frames), its trajectory's pose lines.
std::string LibraryPoses(const RgbdDataset& ds, const Settings& settings, const std::string& spec,
                         const std::string& out) {
  RunOptions options;
  options.out_dir = out;
  options.slam = SlamOptionsFromSettings(settings, 7);
  const std::unique_ptr<Segmenter> segmenter =
      MakeSegmenter(spec, ds.dir(), ResolveSettings(settings).segmenter, "");
  detslam::Run(ds, settings, options, nullptr, segmenter.get());
  return PosesOf((fs::path(out) / "trajectory.txt").string());
}

class IntegrationRosNode : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    work_ = testing::TempDir("ros_node");
    // A master of our own on a port of our own; logs in the test's folder.
    const int port = 20000 + static_cast<int>(::getpid() % 20000);
    const std::string uri = "http://localhost:" + std::to_string(port);
    setenv("ROS_MASTER_URI", uri.c_str(), 1);
    setenv("ROS_LOG_DIR", work_.c_str(), 1);
    setenv("ROS_HOME", work_.c_str(), 1);
    master_ = std::make_unique<testing::ChildProcess>(
        DETSLAM_ROSMASTER, std::vector<std::string>{"--core", "-p", std::to_string(port)},
        fs::path(work_) / "master.log");
    int argc = 1;
    char name[] = "detslam_ros_test";
    char* argv[] = {name, nullptr};
    ros::init(argc, argv, "detslam_ros_test", ros::init_options::NoSigintHandler);
    ros::Time::init();
    const auto end = std::chrono::steady_clock::now() + 30s;
    while (!ros::master::check() && std::chrono::steady_clock::now() < end) {
      std::this_thread::sleep_for(100ms);
    }

    seq_ = integration::WritePresetSequence("ros_node_seq", "walking_xyz", 3, kFrames);
  }
  static void TearDownTestSuite() {
    ros::shutdown();
    master_.reset();
  }
  static std::string work_, seq_;
  static std::unique_ptr<testing::ChildProcess> master_;
};
std::string IntegrationRosNode::work_, IntegrationRosNode::seq_;
std::unique_ptr<testing::ChildProcess> IntegrationRosNode::master_;

TEST_F(IntegrationRosNode, TracksPublishedFramesAndSavesTheLibrarysTrajectory) {
  ASSERT_TRUE(ros::master::check()) << testing::ReadFileBytes(fs::path(work_) / "master.log");
  const std::string config = (fs::path(seq_) / "settings.yaml").string();
  const std::string masks = "masks:" + (fs::path(seq_) / "masks").string();
  const std::string out = testing::TempDir("ros_node_out");
  const fs::path node_log = fs::path(work_) / "node.log";
  testing::ChildProcess node(DETSLAM_ROS_NODE_PATH,
                             {"__name:=detslam", "_config:=" + config, "_segmenter:=" + masks,
                              "_out_dir:=" + out, "_seed:=7", "_queue_size:=100"},
                             node_log);

  ros::NodeHandle nh;
  ros::Publisher rgb_pub = nh.advertise<sensor_msgs::Image>("/camera/rgb/image_color", 100);
  ros::Publisher depth_pub = nh.advertise<sensor_msgs::Image>("/camera/depth/image", 100);
  NodeOutputs outputs(nh, "/detslam");
  ASSERT_TRUE(SpinUntil(
      [&] {
        return rgb_pub.getNumSubscribers() > 0 && depth_pub.getNumSubscribers() > 0 &&
               outputs.Connected();
      },
      60s))
      << testing::ReadFileBytes(node_log);

  // One frame at a time: the next is published once the node has segmented this one (each frame
  // publishes a mask), so that no frame is dropped and the run is comparable with the library's.
  const RgbdDataset ds = RgbdDataset::Open(seq_, {});
  const Settings settings = ReadSettings(config);
  for (size_t i = 0; i < ds.size(); ++i) {
    const RgbdImages im = ds.Load(i, settings.camera);
    cv::Mat rgb;
    cv::cvtColor(im.bgr, rgb, cv::COLOR_BGR2RGB);
    depth_pub.publish(ImageMsg(ds.frame(i).depth_stamp, im.depth_m, "32FC1"));
    rgb_pub.publish(ImageMsg(ds.frame(i).rgb_stamp, rgb, "rgb8"));
    ASSERT_TRUE(SpinUntil([&] { return outputs.masks > static_cast<int>(i); }, 30s))
        << "frame " << i << "\n" << testing::ReadFileBytes(node_log);
  }
  ASSERT_TRUE(SpinUntil([&] { return outputs.poses.size() >= ds.size(); }, 10s));
  EXPECT_EQ(outputs.poses.size(), ds.size());
  EXPECT_GT(outputs.masks_with_objects, kFrames / 2);  // the people are in view most of the time
  EXPECT_GT(outputs.most_points, 500u);
  EXPECT_EQ(outputs.poses.back().header.frame_id, "world");

  // The published (as tracked) poses against ground truth.
  const Trajectory gt = ReadTumTrajectory((fs::path(seq_) / "groundtruth.txt").string());
  const EvalResult live = Evaluate(gt, outputs.Published(), {}, {});
  EXPECT_LT(live.ate.error_m.rmse, 0.02) << "ATE of the published poses";

  // ~save_trajectory: the final poses, equal to the library's sequential run on the same frames.
  std_srvs::Trigger trigger;
  ASSERT_TRUE(ros::service::call("/detslam/save_trajectory", trigger));
  ASSERT_TRUE(trigger.response.success) << trigger.response.message;
  const std::string library = LibraryPoses(ds, settings, masks, testing::TempDir("ros_node_library_out"));
  EXPECT_EQ(std::count(library.begin(), library.end(), '\n'), kFrames);
  EXPECT_EQ(PosesOf(trigger.response.message), library);

  ASSERT_TRUE(ros::service::call("/detslam/save_map", trigger));
  EXPECT_TRUE(trigger.response.success) << trigger.response.message;
  EXPECT_TRUE(fs::is_regular_file(fs::path(out) / "map.dslmap"));

  // SIGINT: the node writes its trajectory and exits cleanly.
  fs::remove(fs::path(out) / "trajectory.txt");
  node.Signal(SIGINT);
  EXPECT_EQ(node.Wait(30s), 0) << testing::ReadFileBytes(node_log);
  EXPECT_EQ(PosesOf((fs::path(out) / "trajectory.txt").string()), library);
}

// `rosbag play` of a bag written by the rosbag C++ API, the node started without settings (the
// camera from the camera info) and without a segmenter.
TEST_F(IntegrationRosNode, FollowsRosbagPlayWithTheCameraInfo) {
  ASSERT_TRUE(ros::master::check());
  const std::string bag = testing::TempPath("ros_node_play.bag");
  testing::WriteSequenceBag(seq_, bag, rosbag::compression::LZ4, testing::DepthEncoding::kMetres32F);
  const std::string out = testing::TempDir("ros_node_play_out");
  const fs::path node_log = fs::path(work_) / "node_play.log";
  testing::ChildProcess node(DETSLAM_ROS_NODE_PATH,
                             {"__name:=detslam_play", "_segmenter:=none", "_out_dir:=" + out,
                              "_seed:=7", "_queue_size:=100"},
                             node_log);
  ros::NodeHandle nh;
  // Another name than the first test's node: parameters stay on the master after a node exits.
  NodeOutputs outputs(nh, "/detslam_play");
  ASSERT_TRUE(SpinUntil([&] { return outputs.pose.getNumPublishers() > 0; }, 60s))
      << testing::ReadFileBytes(node_log);
  // A quarter of the recorded rate, the queue holding every frame: the node sees them all.
  const fs::path play_log = fs::path(work_) / "play.log";
  testing::ChildProcess play(DETSLAM_ROSBAG,
                             {"play", "--wait-for-subscribers", "-d", "1", "-r", "0.25", bag,
                              "--topics", "/camera/rgb/image_color", "/camera/depth/image",
                              "/camera/rgb/camera_info"},
                             play_log);
  ASSERT_TRUE(SpinUntil([&] { return outputs.poses.size() >= static_cast<size_t>(kFrames); }, 120s))
      << outputs.poses.size() << " poses\n" << testing::ReadFileBytes(node_log) << "\n"
      << testing::ReadFileBytes(play_log);
  EXPECT_EQ(play.Wait(30s), 0) << testing::ReadFileBytes(play_log);
  EXPECT_EQ(outputs.masks, 0);  // no segmenter

  std_srvs::Trigger trigger;
  ASSERT_TRUE(ros::service::call("/detslam_play/save_trajectory", trigger));
  ASSERT_TRUE(trigger.response.success) << trigger.response.message;
  EXPECT_NE(testing::ReadFileBytes(node_log).find("settings: camera info in topic"), std::string::npos)
      << testing::ReadFileBytes(node_log);
  // The library on the folder with the settings the camera info gives.
  const RgbdDataset ds = RgbdDataset::Open(seq_, {});
  const Settings folder_settings = ReadSettings((fs::path(seq_) / "settings.yaml").string());
  RosCameraInfo info;
  info.width = static_cast<uint32_t>(folder_settings.camera.width);
  info.height = static_cast<uint32_t>(folder_settings.camera.height);
  info.distortion_model = "plumb_bob";
  info.d = {0, 0, 0, 0, 0};
  info.k = {folder_settings.camera.fx, 0, folder_settings.camera.cx, 0, folder_settings.camera.fy,
            folder_settings.camera.cy, 0, 0, 1};
  const std::string library = LibraryPoses(ds, SettingsFromCameraInfo(info, "test"), "none",
                                           testing::TempDir("ros_node_play_library_out"));
  EXPECT_EQ(std::count(library.begin(), library.end(), '\n'), kFrames);
  EXPECT_EQ(PosesOf(trigger.response.message), library);
  node.Signal(SIGINT);
  EXPECT_EQ(node.Wait(30s), 0) << testing::ReadFileBytes(node_log);
}

}  // namespace
}  // namespace detslam
