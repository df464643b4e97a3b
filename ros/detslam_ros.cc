// detslam_ros: detslam as a ROS 1 node. Subscribes to a colour and a depth sensor_msgs/Image topic
// (paired by header stamp) and the camera info; runs the Det-SLAM stage and SLAM on each pair in
// the callback thread (frames that arrive while one is processed wait in the subscriber queue of
// `queue_size` and the oldest are dropped, as a live camera's would be); publishes
//   ~pose           geometry_msgs/PoseStamped, the camera in `world_frame` (as tracked)
//   /tf             world_frame -> camera frame (tf2_msgs/TFMessage)
//   ~map_points     sensor_msgs/PointCloud2 (x y z float32) of every map point, after each keyframe
//   ~dynamic_mask   sensor_msgs/Image mono8, 255 on the dynamic objects of segmented frames
// and offers ~save_trajectory and ~save_map (std_srvs/Trigger: out_dir/trajectory.txt with the
// final poses, out_dir/map.dslmap). On shutdown it writes trajectory.txt.
// Private parameters: config (settings YAML; default: the camera info with the fr3 preset's other
// values), segmenter (dnn|none|masks:DIR; default dnn when its models are found), models,
// vocabulary, seed, out_dir, rgb_topic, depth_topic, camera_info_topic, world_frame,
// camera_frame (default: the colour images' frame_id), max_dt, queue_size.
#include <geometry_msgs/PoseStamped.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_srvs/Trigger.h>
#include <tf2_msgs/TFMessage.h>

#include <cmath>
#include <cstring>
#include <deque>
#include <filesystem>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <string>

#include "detslam/core/check.h"
#include "detslam/io/rosbag_source.h"
#include "detslam/io/settings.h"
#include "detslam/io/trajectory.h"
#include "detslam/pipeline/runner.h"
#include "detslam/pipeline/settings_keys.h"
#include "detslam/segmentation/dnn_segmenter.h"
#include "detslam/segmentation/segmenter_factory.h"

namespace detslam::ros_node {
namespace {
namespace fs = std::filesystem;

Timestamp ToStamp(const ros::Time& t) {
  return Timestamp{static_cast<int64_t>(t.sec) * 1000000000 + t.nsec};
}

// A view of a roscpp image as detslam's RosImage (no copy).
RosImage View(const sensor_msgs::Image& m) {
  RosImage im;
  im.header.seq = m.header.seq;
  im.header.stamp = ToStamp(m.header.stamp);
  im.header.frame_id = m.header.frame_id;
  im.height = m.height;
  im.width = m.width;
  im.encoding = m.encoding;
  im.big_endian = m.is_bigendian != 0;
  im.step = m.step;
  im.data = m.data.data();
  im.data_size = m.data.size();
  if (static_cast<uint64_t>(im.height) * im.step > im.data_size) {
    throw std::runtime_error("image data holds fewer bytes than height * step");
  }
  return im;
}

RosCameraInfo ToInfo(const sensor_msgs::CameraInfo& m) {
  RosCameraInfo info;
  info.header.stamp = ToStamp(m.header.stamp);
  info.header.frame_id = m.header.frame_id;
  info.width = m.width;
  info.height = m.height;
  info.distortion_model = m.distortion_model;
  info.d = m.D;
  for (int i = 0; i < 9; ++i) info.k[i] = m.K[i];
  return info;
}

class Node {
 public:
  Node(ros::NodeHandle& nh, ros::NodeHandle& pnh) {
    pnh.param<std::string>("config", config_, "");
    pnh.param<std::string>("segmenter", segmenter_spec_, "");
    pnh.param<std::string>("models", models_, "");
    pnh.param<std::string>("vocabulary", vocabulary_, "");
    int seed = 42;
    pnh.param("seed", seed, 42);
    seed_ = static_cast<uint64_t>(seed);
    pnh.param<std::string>("out_dir", out_dir_, "detslam_ros_out");
    pnh.param<std::string>("world_frame", world_frame_, "world");
    pnh.param<std::string>("camera_frame", camera_frame_, "");
    pnh.param("max_dt", max_dt_, 0.02);
    int queue = 5;
    pnh.param("queue_size", queue, 5);
    std::string rgb_topic, depth_topic, info_topic;
    pnh.param<std::string>("rgb_topic", rgb_topic, "/camera/rgb/image_color");
    pnh.param<std::string>("depth_topic", depth_topic, "/camera/depth/image");
    pnh.param<std::string>("camera_info_topic", info_topic, "/camera/rgb/camera_info");

    if (!config_.empty()) Start(ReadSettings(config_));
    pose_pub_ = pnh.advertise<geometry_msgs::PoseStamped>("pose", 10);
    tf_pub_ = nh.advertise<tf2_msgs::TFMessage>("/tf", 10);
    points_pub_ = pnh.advertise<sensor_msgs::PointCloud2>("map_points", 1, true);
    mask_pub_ = pnh.advertise<sensor_msgs::Image>("dynamic_mask", 2);
    rgb_sub_ = nh.subscribe(rgb_topic, static_cast<uint32_t>(queue), &Node::OnColour, this);
    depth_sub_ = nh.subscribe(depth_topic, static_cast<uint32_t>(queue), &Node::OnDepth, this);
    info_sub_ = nh.subscribe(info_topic, 1, &Node::OnCameraInfo, this);
    save_trajectory_ = pnh.advertiseService("save_trajectory", &Node::SaveTrajectory, this);
    save_map_ = pnh.advertiseService("save_map", &Node::SaveMap, this);
    ROS_INFO("detslam_ros: colour %s, depth %s, camera info %s; outputs in %s", rgb_topic.c_str(),
             depth_topic.c_str(), info_topic.c_str(), out_dir_.c_str());
  }

  // Writes trajectory.txt (the final poses of the frames tracked so far).
  std::string WriteTrajectory() {
    if (!slam_) throw InputError("no frame processed yet (no camera settings)");
    fs::create_directories(out_dir_);
    const std::string path = (fs::path(out_dir_) / "trajectory.txt").string();
    WriteTumTrajectory(path, slam_->FrameTrajectory(),
                       "detslam_ros trajectory (world_from_camera), " + std::to_string(frames_) +
                           " frames processed");
    return path;
  }
  bool started() const { return slam_ != nullptr; }

 private:
  void Start(const Settings& settings) {
    settings_ = settings;
    const ResolvedSettings resolved = ResolveSettings(settings_);
    SlamOptions options = SlamOptionsFromSettings(settings_, seed_);
    if (!vocabulary_.empty()) options.vocabulary = vocabulary_;
    const std::string models = models_.empty() ? DefaultModelsDir() : models_;
    if (segmenter_spec_.empty()) {
      try {
        segmenter_ = MakeSegmenter("dnn", "", resolved.segmenter, models);
      } catch (const InputError& e) {
        ROS_WARN("detslam_ros: no dynamic-object segmentation (set ~segmenter): %s", e.what());
      }
    } else {
      segmenter_ = MakeSegmenter(segmenter_spec_, "", resolved.segmenter, models);
    }
    slam_ = std::make_unique<SlamSystem>(settings_.camera, options, segmenter_.get());
    ROS_INFO("detslam_ros: started (settings: %s, camera %dx%d fx %.1f)", settings_.source.c_str(),
             settings_.camera.width, settings_.camera.height, settings_.camera.fx);
  }

  void OnCameraInfo(const sensor_msgs::CameraInfoConstPtr& m) {
    if (slam_) return;
    try {
      Start(SettingsFromCameraInfo(ToInfo(*m), "topic " + info_sub_.getTopic()));
    } catch (const std::exception& e) {
      ROS_ERROR_THROTTLE(5, "detslam_ros: cannot start from the camera info: %s", e.what());
      return;
    }
    Pair();  // the frames that came before it
  }
  void OnColour(const sensor_msgs::ImageConstPtr& m) {
    rgb_.push_back(m);
    Pair();
  }
  void OnDepth(const sensor_msgs::ImageConstPtr& m) {
    depth_.push_back(m);
    Pair();
  }

  // Pairs the oldest colour image with a depth image within max_dt (greedy, in stamp order);
  // drops what can no longer be paired. Until the camera is known (camera info), the newest
  // kWaiting images of each stream wait.
  void Pair() {
    if (!slam_) {
      while (rgb_.size() > kWaiting) rgb_.pop_front();
      while (depth_.size() > kWaiting) depth_.pop_front();
      ROS_WARN_THROTTLE(5, "detslam_ros: waiting for camera info on %s (or set ~config)",
                        info_sub_.getTopic().c_str());
      return;
    }
    while (!rgb_.empty() && !depth_.empty()) {
      const Timestamp c = ToStamp(rgb_.front()->header.stamp);
      size_t best = depth_.size();
      double best_dt = max_dt_;
      for (size_t j = 0; j < depth_.size(); ++j) {
        const double dt = AbsDiffSeconds(c, ToStamp(depth_[j]->header.stamp));
        if (dt < best_dt) {
          best_dt = dt;
          best = j;
        }
      }
      if (best < depth_.size()) {
        const sensor_msgs::ImageConstPtr rgb = rgb_.front(), depth = depth_[best];
        rgb_.pop_front();
        depth_.erase(depth_.begin(), depth_.begin() + static_cast<long>(best) + 1);
        Process(*rgb, *depth);
        continue;
      }
      // No partner yet: wait while a newer depth image could still come, else drop.
      if (ToStamp(depth_.back()->header.stamp).Seconds() < c.Seconds() + max_dt_ &&
          rgb_.size() < kWaiting)
        break;
      rgb_.pop_front();
    }
    while (depth_.size() > kWaiting) depth_.pop_front();
  }

  void Process(const sensor_msgs::Image& rgb_msg, const sensor_msgs::Image& depth_msg) {
    const Timestamp stamp = ToStamp(rgb_msg.header.stamp);
    cv::Mat bgr, depth;
    try {
      bgr = RosImageToBgr(View(rgb_msg), "colour: ");
      depth = RosImageToDepthMetres(View(depth_msg), "depth: ");
    } catch (const std::exception& e) {
      ROS_ERROR_THROTTLE(5, "detslam_ros: frame %s skipped: %s", stamp.ToString().c_str(), e.what());
      return;
    }
    if (bgr.cols != settings_.camera.width || bgr.rows != settings_.camera.height ||
        depth.size() != bgr.size()) {
      ROS_ERROR_THROTTLE(5, "detslam_ros: frame %s skipped: colour %s, depth %s, camera %s",
                         stamp.ToString().c_str(), ImageSizeText(bgr.cols, bgr.rows).c_str(),
                         ImageSizeText(depth.cols, depth.rows).c_str(),
                         ImageSizeText(settings_.camera.width, settings_.camera.height).c_str());
      return;
    }
    cv::Mat gray;
    cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
    const int64_t index = frames_++;
    SegmenterInput in;
    in.index = index;
    in.stamp = stamp;
    in.bgr = bgr;
    in.depth_m = depth;
    const FrameInstances dynamic = slam_->SegmentFrame(in, gray);
    FrameReport report;
    report.segmentation_ms = dynamic.segmentation_ms;
    Frame frame = slam_->ExtractFrame(index, stamp, gray, depth, cv::Mat(), &report,
                                      dynamic.segmented ? &dynamic.instances : nullptr);
    const KeyFrameId kf = slam_->TrackFrame(std::move(frame), &report);
    if (kf != kNoKeyFrame) slam_->MapKeyFrame(kf, &report);

    const std::string camera_frame = camera_frame_.empty() ? rgb_msg.header.frame_id : camera_frame_;
    if (report.tracking.pose_valid) PublishPose(rgb_msg.header.stamp, camera_frame, report.world_from_cam);
    if (dynamic.segmented) PublishMask(rgb_msg.header, dynamic, bgr.size());
    if (kf != kNoKeyFrame) PublishMapPoints(rgb_msg.header.stamp);
  }

  void PublishPose(const ros::Time& stamp, const std::string& camera_frame, const Rigid3d& pose) {
    geometry_msgs::PoseStamped p;
    p.header.stamp = stamp;
    p.header.frame_id = world_frame_;
    p.pose.position.x = pose.translation().x();
    p.pose.position.y = pose.translation().y();
    p.pose.position.z = pose.translation().z();
    p.pose.orientation.x = pose.rotation().x();
    p.pose.orientation.y = pose.rotation().y();
    p.pose.orientation.z = pose.rotation().z();
    p.pose.orientation.w = pose.rotation().w();
    pose_pub_.publish(p);
    geometry_msgs::TransformStamped t;
    t.header = p.header;
    t.child_frame_id = camera_frame;
    t.transform.translation.x = p.pose.position.x;
    t.transform.translation.y = p.pose.position.y;
    t.transform.translation.z = p.pose.position.z;
    t.transform.rotation = p.pose.orientation;
    tf2_msgs::TFMessage tf;
    tf.transforms.push_back(t);
    tf_pub_.publish(tf);
  }

  void PublishMask(const std_msgs::Header& header, const FrameInstances& dynamic, cv::Size size) {
    cv::Mat mask(size, CV_8UC1, cv::Scalar(0));
    for (const Instance& inst : dynamic.instances) {
      if (!inst.mask.empty() && inst.mask.size() == size) {
        mask.setTo(255, inst.mask);
      } else {
        mask(inst.box & cv::Rect(0, 0, size.width, size.height)).setTo(255);
      }
    }
    sensor_msgs::Image m;
    m.header = header;
    m.height = static_cast<uint32_t>(size.height);
    m.width = static_cast<uint32_t>(size.width);
    m.encoding = "mono8";
    m.step = m.width;
    m.data.assign(mask.datastart, mask.dataend);
    mask_pub_.publish(m);
  }

  void PublishMapPoints(const ros::Time& stamp) {
    sensor_msgs::PointCloud2 cloud;
    cloud.header.stamp = stamp;
    cloud.header.frame_id = world_frame_;
    const char* names[] = {"x", "y", "z"};
    for (uint32_t i = 0; i < 3; ++i) {
      sensor_msgs::PointField f;
      f.name = names[i];
      f.offset = 4 * i;
      f.datatype = sensor_msgs::PointField::FLOAT32;
      f.count = 1;
      cloud.fields.push_back(f);
    }
    cloud.point_step = 12;
    cloud.is_bigendian = false;
    cloud.is_dense = true;
    cloud.height = 1;
    {
      const auto map = slam_->ReadMap();
      cloud.data.reserve(map->landmarks().size() * 12);
      for (const auto& [id, lm] : map->landmarks()) {
        const float xyz[3] = {static_cast<float>(lm.position.x()), static_cast<float>(lm.position.y()),
                              static_cast<float>(lm.position.z())};
        const uint8_t* b = reinterpret_cast<const uint8_t*>(xyz);
        cloud.data.insert(cloud.data.end(), b, b + 12);
      }
    }
    cloud.width = static_cast<uint32_t>(cloud.data.size() / 12);
    cloud.row_step = cloud.point_step * cloud.width;
    points_pub_.publish(cloud);
  }

  bool SaveTrajectory(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
    try {
      res.message = WriteTrajectory();
      res.success = true;
    } catch (const std::exception& e) {
      res.success = false;
      res.message = e.what();
    }
    return true;
  }
  bool SaveMap(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
    try {
      if (!slam_) throw InputError("no frame processed yet (no camera settings)");
      fs::create_directories(out_dir_);
      const std::string path = (fs::path(out_dir_) / "map.dslmap").string();
      slam_->WaitForGlobalBundleAdjustment();
      const uint64_t bytes = slam_->SaveMap(path);
      res.message = path + " (" + std::to_string(bytes) + " bytes)";
      res.success = true;
    } catch (const std::exception& e) {
      res.success = false;
      res.message = e.what();
    }
    return true;
  }

  static constexpr size_t kWaiting = 10;  // images of a stream kept for pairing
  std::string config_, segmenter_spec_, models_, vocabulary_, out_dir_, world_frame_, camera_frame_;
  uint64_t seed_ = 42;
  double max_dt_ = 0.02;
  Settings settings_;
  std::unique_ptr<Segmenter> segmenter_;
  std::unique_ptr<SlamSystem> slam_;
  int64_t frames_ = 0;
  std::deque<sensor_msgs::ImageConstPtr> rgb_, depth_;
  ros::Publisher pose_pub_, tf_pub_, points_pub_, mask_pub_;
  ros::Subscriber rgb_sub_, depth_sub_, info_sub_;
  ros::ServiceServer save_trajectory_, save_map_;
};

}  // namespace
}  // namespace detslam::ros_node

int main(int argc, char** argv) {
  ros::init(argc, argv, "detslam");
  ros::NodeHandle nh, pnh("~");
  try {
    detslam::ros_node::Node node(nh, pnh);
    ros::spin();
    if (node.started()) ROS_INFO("detslam_ros: wrote %s", node.WriteTrajectory().c_str());
  } catch (const std::exception& e) {
    ROS_FATAL("detslam_ros: %s", e.what());
    return 1;
  }
  return 0;
}
