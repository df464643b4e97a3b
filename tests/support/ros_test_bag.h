// Test helpers for ROS 1 tests (tests/rosbag, ros/): roscpp messages from detslam data, and a
// synthetic sequence folder written as a bag with ROS's rosbag C++ API. Header-only; include it
// only from targets built with the ROS headers.
#pragma once

#include <geometry_msgs/TransformStamped.h>
#include <rosbag/bag.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <tf2_msgs/TFMessage.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <opencv2/imgproc.hpp>
#include <string>

#include "detslam/io/dataset.h"
#include "detslam/io/settings.h"
#include "detslam/io/trajectory.h"

namespace detslam::testing {

enum class DepthEncoding { kMetres32F, kMillimetres16U };

inline ros::Time RosTime(Timestamp t) {
  ros::Time r;
  r.sec = static_cast<uint32_t>(t.ns / 1000000000);
  r.nsec = static_cast<uint32_t>(t.ns % 1000000000);
  return r;
}

inline sensor_msgs::Image ImageMsg(Timestamp t, const cv::Mat& m, const std::string& encoding) {
  sensor_msgs::Image im;
  im.header.stamp = RosTime(t);
  im.header.frame_id = "camera_rgb_optical_frame";
  im.height = static_cast<uint32_t>(m.rows);
  im.width = static_cast<uint32_t>(m.cols);
  im.encoding = encoding;
  im.is_bigendian = 0;
  im.step = static_cast<uint32_t>(m.cols * m.elemSize());
  im.data.resize(static_cast<size_t>(im.step) * m.rows);
  for (int y = 0; y < m.rows; ++y) std::memcpy(&im.data[y * im.step], m.ptr(y), im.step);
  return im;
}

// The fixed transform from the camera's optical frame to the tracked body, as in TUM's bags
// (/kinect -> /openni_rgb_optical_frame on /tf_static).
inline Rigid3d KinectFromCamera() {
  return Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized())),
                 Eigen::Vector3d(0.01, -0.045, 0.02));
}

inline geometry_msgs::TransformStamped TransformMsg(const std::string& parent, const std::string& child,
                                             Timestamp t, const Rigid3d& parent_from_child) {
  geometry_msgs::TransformStamped m;
  m.header.stamp = RosTime(t);
  m.header.frame_id = parent;
  m.child_frame_id = child;
  m.transform.translation.x = parent_from_child.translation().x();
  m.transform.translation.y = parent_from_child.translation().y();
  m.transform.translation.z = parent_from_child.translation().z();
  m.transform.rotation.x = parent_from_child.rotation().x();
  m.transform.rotation.y = parent_from_child.rotation().y();
  m.transform.rotation.z = parent_from_child.rotation().z();
  m.transform.rotation.w = parent_from_child.rotation().w();
  return m;
}

// Writes the folder sequence `dir` as a bag with TUM's topic names, the way `rosbag record`
// stores a Kinect driver's output (receipt times a little after the header stamps), with the
// ground truth on /tf and /tf_static.
inline void WriteSequenceBag(const std::string& dir, const std::string& path, uint32_t compression,
                             DepthEncoding depth) {
  namespace fs = std::filesystem;
  const RgbdDataset ds = RgbdDataset::Open(dir, {});
  const Settings settings = ReadSettings((fs::path(dir) / "settings.yaml").string());
  rosbag::Bag bag;
  bag.open(path, rosbag::bagmode::Write);
  bag.setCompression(static_cast<rosbag::compression::CompressionType>(compression));
  // Ground truth as TUM's bags carry it: the tracked body in /world on /tf (here at the frames'
  // stamps), the body-to-camera transform once on /tf_static.
  tf2_msgs::TFMessage fixed;
  fixed.transforms.push_back(
      TransformMsg("/kinect", "/camera_rgb_optical_frame", Timestamp{0}, KinectFromCamera()));
  bag.write("/tf_static", RosTime(ds.frame(0).rgb_stamp), fixed);
  for (const StampedPose& p : ReadTumTrajectory((fs::path(dir) / "groundtruth.txt").string())) {
    tf2_msgs::TFMessage moving;
    moving.transforms.push_back(TransformMsg("/world", "/kinect", p.stamp,
                                             p.world_from_cam * KinectFromCamera().Inverse()));
    bag.write("/tf", RosTime(p.stamp), moving);
  }
  for (size_t i = 0; i < ds.size(); ++i) {
    const RgbdImages im = ds.Load(i, settings.camera);
    const Timestamp t = ds.frame(i).rgb_stamp, td = ds.frame(i).depth_stamp;
    const ros::Time received = RosTime(Timestamp{t.ns + 3000000});
    {  // with every frame, as camera drivers publish it
      sensor_msgs::CameraInfo info;
      info.header.stamp = RosTime(t);
      info.width = settings.camera.width;
      info.height = settings.camera.height;
      info.distortion_model = "plumb_bob";
      info.D = {0, 0, 0, 0, 0};
      info.K = {settings.camera.fx, 0, settings.camera.cx, 0, settings.camera.fy,
                settings.camera.cy, 0, 0, 1};
      bag.write("/camera/rgb/camera_info", received, info);
    }
    cv::Mat rgb;
    cv::cvtColor(im.bgr, rgb, cv::COLOR_BGR2RGB);
    bag.write("/camera/rgb/image_color", received, ImageMsg(t, rgb, "rgb8"));
    if (depth == DepthEncoding::kMetres32F) {
      bag.write("/camera/depth/image", received, ImageMsg(td, im.depth_m, "32FC1"));
    } else {
      cv::Mat mm(im.depth_m.size(), CV_16UC1);
      for (int y = 0; y < mm.rows; ++y)
        for (int x = 0; x < mm.cols; ++x)
          mm.at<uint16_t>(y, x) = static_cast<uint16_t>(std::lround(im.depth_m.at<float>(y, x) * 1000));
      bag.write("/camera/depth/image", received, ImageMsg(td, mm, "16UC1"));
    }
  }
  bag.close();
}

}  // namespace detslam::testing
