#include "detslam/io/ros_messages.h"

#include <cstring>
#include <stdexcept>

namespace detslam {
namespace {

// Reads the ROS 1 wire format with bounds checks.
class WireReader {
 public:
  WireReader(const uint8_t* p, size_t n, const char* message) : p_(p), n_(n), message_(message) {}

  uint8_t U8(const char* field) { return *Take(1, field); }
  uint32_t U32(const char* field) {
    const uint8_t* b = Take(4, field);
    return static_cast<uint32_t>(b[0]) | static_cast<uint32_t>(b[1]) << 8 |
           static_cast<uint32_t>(b[2]) << 16 | static_cast<uint32_t>(b[3]) << 24;
  }
  double F64(const char* field) {
    double v;
    std::memcpy(&v, Take(8, field), 8);  // little-endian hosts only (x86-64, arm64)
    return v;
  }
  std::string String(const char* field) {
    const uint32_t len = U32(field);
    const uint8_t* b = Take(len, field);
    return std::string(reinterpret_cast<const char*>(b), len);
  }
  // A uint8[] field: its length, then the bytes (returned as a view).
  const uint8_t* Bytes(const char* field, size_t* size) {
    *size = U32(field);
    return Take(*size, field);
  }
  RosHeader Header() {
    RosHeader h;
    h.seq = U32("header.seq");
    const uint32_t sec = U32("header.stamp.sec");
    const uint32_t nsec = U32("header.stamp.nsec");
    h.stamp = Timestamp{static_cast<int64_t>(sec) * 1000000000 + nsec};
    h.frame_id = String("header.frame_id");
    return h;
  }
  void End() const {
    if (i_ != n_) {
      throw std::runtime_error(std::string(message_) + ": " + std::to_string(n_ - i_) +
                               " bytes left over after the last field (another message type?)");
    }
  }

 private:
  const uint8_t* Take(size_t k, const char* field) {
    if (k > n_ - i_) {
      throw std::runtime_error(std::string(message_) + " ends inside field '" + field + "' (" +
                               std::to_string(k) + " bytes wanted, " + std::to_string(n_ - i_) +
                               " left)");
    }
    const uint8_t* b = p_ + i_;
    i_ += k;
    return b;
  }
  const uint8_t* p_;
  size_t n_, i_ = 0;
  const char* message_;
};

}  // namespace

RosImage ParseRosImage(const uint8_t* bytes, size_t size) {
  WireReader r(bytes, size, "sensor_msgs/Image");
  RosImage im;
  im.header = r.Header();
  im.height = r.U32("height");
  im.width = r.U32("width");
  im.encoding = r.String("encoding");
  im.big_endian = r.U8("is_bigendian") != 0;
  im.step = r.U32("step");
  im.data = r.Bytes("data", &im.data_size);
  r.End();
  if (static_cast<uint64_t>(im.height) * im.step != im.data_size) {
    throw std::runtime_error("sensor_msgs/Image: data holds " + std::to_string(im.data_size) +
                             " bytes, height * step = " + std::to_string(im.height) + " * " +
                             std::to_string(im.step));
  }
  return im;
}

RosCompressedImage ParseRosCompressedImage(const uint8_t* bytes, size_t size) {
  WireReader r(bytes, size, "sensor_msgs/CompressedImage");
  RosCompressedImage im;
  im.header = r.Header();
  im.format = r.String("format");
  im.data = r.Bytes("data", &im.data_size);
  r.End();
  return im;
}

RosCameraInfo ParseRosCameraInfo(const uint8_t* bytes, size_t size) {
  WireReader r(bytes, size, "sensor_msgs/CameraInfo");
  RosCameraInfo c;
  c.header = r.Header();
  c.height = r.U32("height");
  c.width = r.U32("width");
  c.distortion_model = r.String("distortion_model");
  const uint32_t nd = r.U32("D");
  if (nd > size / 8) throw std::runtime_error("sensor_msgs/CameraInfo: impossible length of D");
  for (uint32_t i = 0; i < nd; ++i) c.d.push_back(r.F64("D"));
  for (double& k : c.k) k = r.F64("K");
  for (int i = 0; i < 9 + 12; ++i) r.F64(i < 9 ? "R" : "P");
  r.U32("binning_x");
  r.U32("binning_y");
  for (const char* f : {"roi.x_offset", "roi.y_offset", "roi.height", "roi.width"}) r.U32(f);
  r.U8("roi.do_rectify");
  r.End();
  return c;
}

std::vector<RosTransform> ParseRosTfMessage(const uint8_t* bytes, size_t size) {
  WireReader r(bytes, size, "tf2_msgs/TFMessage");
  const uint32_t n = r.U32("transforms");
  if (n > size / 16) throw std::runtime_error("tf2_msgs/TFMessage: impossible transform count");
  std::vector<RosTransform> out(n);
  for (RosTransform& t : out) {
    t.header = r.Header();
    t.child_frame_id = r.String("child_frame_id");
    for (double& v : t.translation) v = r.F64("transform.translation");
    for (double& v : t.rotation) v = r.F64("transform.rotation");
  }
  r.End();
  return out;
}

Timestamp ParseRosHeaderStamp(const uint8_t* bytes, size_t size) {
  WireReader r(bytes, size, "message header");
  return r.Header().stamp;
}

}  // namespace detslam
