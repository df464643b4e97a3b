// RGB-D frames from a ROS 1 bag: colour and depth sensor_msgs/Image topics (TUM RGB-D bags by
// default), paired by header stamp as the TUM tools pair rgb.txt and depth.txt, and the camera
// intrinsics from a sensor_msgs/CameraInfo topic.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "detslam/io/rgbd_source.h"
#include "detslam/io/ros_messages.h"
#include "detslam/io/rosbag_file.h"
#include "detslam/io/settings.h"

namespace detslam {

struct RosbagOptions {
  // sensor_msgs/Image rgb8, bgr8, mono8 (also rgba8, bgra8), or CompressedImage (JPEG, PNG)
  std::string rgb_topic = "/camera/rgb/image_color";
  // sensor_msgs/Image 32FC1 metres or 16UC1 millimetres, or CompressedImage (compressedDepth)
  std::string depth_topic = "/camera/depth/image";
  std::string camera_info_topic = "/camera/rgb/camera_info";  // optional in the bag
  double max_difference_s = 0.02;  // colour<->depth association window (TUM associate.py), s
  double offset_s = 0.0;           // added to depth stamps before association, seconds

  bool Check(std::string* error) const;
};

class RosbagSource : public RgbdSource {
 public:
  // Scans the bag and pairs the frames. Throws InputError naming the bag for a missing topic (the
  // message lists the image topics the bag has), a topic of another message type, a message that
  // does not parse, or no pair within the window.
  static RosbagSource Open(const std::string& path, const RosbagOptions& options);

  size_t size() const override { return frames_.size(); }
  Timestamp stamp(size_t i) const override;
  Timestamp depth_stamp(size_t i) const;
  // Decodes frame i. Colour of any supported encoding becomes BGR; depth becomes metres (16UC1 is
  // read as millimetres, REP 118; NaN, infinite and negative values become 0 = missing, whatever
  // DepthMapFactor says). Throws InputError naming the bag, topic and stamp for an unsupported
  // encoding or a size other than the camera's.
  RgbdImages Load(size_t i, const PinholeCamera& camera) const override;
  const std::string& name() const override { return path_; }
  std::string groundtruth_path() const override { return std::string(); }

  // The first message on the camera-info topic, if the bag has one.
  const std::optional<RosCameraInfo>& camera_info() const { return camera_info_; }
  const RosbagOptions& options() const { return options_; }
  // Whether the bag has tf topics (`detslam rosbag groundtruth` may then export ground truth).
  bool has_tf() const;
  size_t rgb_messages() const { return rgb_count_; }
  size_t depth_messages() const { return depth_count_; }

 private:
  struct Pair {
    size_t rgb = 0, depth = 0;  // indices into bag_->messages()
    Timestamp rgb_stamp, depth_stamp;
  };
  bool Compressed(const RosbagMessage& m) const;  // a CompressedImage message

  std::string path_;
  RosbagOptions options_;
  std::shared_ptr<const RosbagFile> bag_;
  std::vector<Pair> frames_;
  std::optional<RosCameraInfo> camera_info_;
  size_t rgb_count_ = 0, depth_count_ = 0;
};

// Settings for a bag run without --config: the preset whose name the bag's file name contains
// (freiburg1/fr1, ..., as for folders: the TUM calibration, better than the default intrinsics
// in TUM's own camera_info), else the fr3 preset with the size, intrinsics and plumb_bob
// distortion of `info`. Throws InputError when neither is available.
Settings SettingsForBag(const std::string& bag_path, const std::optional<RosCameraInfo>& info);

// The fr3 preset with the size, intrinsics and plumb_bob distortion of `info` (`source` names
// where it came from, for messages and Settings::source). Throws InputError for another
// distortion model with non-zero coefficients or an invalid camera.
Settings SettingsFromCameraInfo(const RosCameraInfo& info, const std::string& source);

// A colour image (rgb8, bgr8, rgba8, bgra8, mono8) as 8-bit BGR, and a depth image (32FC1 metres,
// 16UC1 millimetres; either byte order) as CV_32FC1 metres with NaN, infinite and negative values
// set to 0 (missing). Both copy the pixels. Throw std::runtime_error starting with `where` for
// another encoding, a size of 0 or over 16384, or a row step shorter than a row.
cv::Mat RosImageToBgr(const RosImage& image, const std::string& where = "");
cv::Mat RosImageToDepthMetres(const RosImage& image, const std::string& where = "");
// The same from sensor_msgs/CompressedImage: colour JPEG or PNG (8-bit, 1, 3 or 4 channels), and
// depth in image_transport's compressedDepth form: a 12-byte header (int32 format, float
// depthQuantA, depthQuantB) then a 16-bit PNG, millimetres for "16UC1; compressedDepth", for
// "32FC1; compressedDepth" quantised inverse depth (depth = depthQuantA / (v - depthQuantB), v = 0
// missing). Throw std::runtime_error starting with `where` when the data does not decode.
cv::Mat RosCompressedToBgr(const RosCompressedImage& image, const std::string& where = "");
cv::Mat RosCompressedToDepthMetres(const RosCompressedImage& image, const std::string& where = "");

}  // namespace detslam
