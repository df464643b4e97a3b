// The ROS 1 messages detslam reads from bags, deserialized from their wire format (little-endian,
// strings and variable arrays prefixed by a uint32 length): sensor_msgs/Image,
// sensor_msgs/CompressedImage, sensor_msgs/CameraInfo and tf2_msgs/TFMessage (= tf/tfMessage).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "detslam/core/timestamp.h"

namespace detslam {

struct RosHeader {
  uint32_t seq = 0;
  Timestamp stamp;
  std::string frame_id;
};

struct RosImage {
  RosHeader header;
  uint32_t height = 0, width = 0;
  std::string encoding;  // rgb8, bgr8, mono8, 16UC1, 32FC1, ...
  bool big_endian = false;
  uint32_t step = 0;           // bytes per row
  const uint8_t* data = nullptr;  // height * step bytes inside the parsed buffer
  size_t data_size = 0;
};

// sensor_msgs/CompressedImage: `format` is "jpeg" / "png" (image_transport's compressed plugin
// writes e.g. "rgb8; jpeg compressed bgr8") or, for depth, "16UC1; compressedDepth png" /
// "32FC1; compressedDepth png" (compressedDepth: a 12-byte header before the PNG).
struct RosCompressedImage {
  RosHeader header;
  std::string format;
  const uint8_t* data = nullptr;  // inside the parsed buffer
  size_t data_size = 0;
};

struct RosCameraInfo {
  RosHeader header;
  uint32_t height = 0, width = 0;
  std::string distortion_model;  // plumb_bob (k1 k2 t1 t2 k3), rational_polynomial, ...
  std::vector<double> d;
  std::array<double, 9> k{};  // row-major 3x3 intrinsics
};

struct RosTransform {
  RosHeader header;  // header.frame_id: the parent frame
  std::string child_frame_id;
  std::array<double, 3> translation{};
  std::array<double, 4> rotation{};  // x y z w
};

// Each throws std::runtime_error naming the field when the bytes end early, a length is
// impossible, or bytes are left over. ParseRosImage also checks that data holds height * step
// bytes; the returned image points into `bytes`.
RosImage ParseRosImage(const uint8_t* bytes, size_t size);
RosCompressedImage ParseRosCompressedImage(const uint8_t* bytes, size_t size);
RosCameraInfo ParseRosCameraInfo(const uint8_t* bytes, size_t size);
std::vector<RosTransform> ParseRosTfMessage(const uint8_t* bytes, size_t size);
// The header stamp of any message that starts with a std_msgs/Header.
Timestamp ParseRosHeaderStamp(const uint8_t* bytes, size_t size);

}  // namespace detslam
