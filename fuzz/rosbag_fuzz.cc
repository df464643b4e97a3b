// Fuzz target: ROS 1 bag files (RosbagFile::Open, the sensor_msgs parsers, RosbagSource::Open and
// Load). Every message's bytes also go through each message parser, whatever its topic, so the
// fuzzer reaches Image, CompressedImage, CameraInfo and
// TFMessage parsing from any connection; Load decodes the compressed images of the default topics.
#include <cstdlib>
#include <stdexcept>

#include "detslam/io/ros_messages.h"
#include "detslam/io/rosbag_file.h"
#include "detslam/io/rosbag_source.h"
#include "fuzz_input.h"

namespace {

// A message parser may refuse bytes with std::runtime_error (the bag reader wraps it into an
// InputError naming the bag); anything else is a bug.
template <typename F>
void Parses(F&& f) {
  try {
    f();
  } catch (const std::runtime_error&) {
  }
}

}  // namespace

// Compressed images that claim a huge size are refused by OpenCV (read once, at its first decode)
// instead of allocating gigabytes.
extern "C" int LLVMFuzzerInitialize(int*, char***) {
  setenv("OPENCV_IO_MAX_IMAGE_PIXELS", "4194304", 1);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace detslam;
  const std::string path = fuzz::WriteInput("input.bag", fuzz::Bytes(data, size));
  fuzz::Accepts([&] {
    RosbagFile::Open(path, [](const RosbagMessage& m, const RosbagConnection&, const uint8_t* b) {
      Parses([&] { ParseRosImage(b, m.size); });
      Parses([&] { ParseRosCompressedImage(b, m.size); });
      Parses([&] { ParseRosCameraInfo(b, m.size); });
      Parses([&] { ParseRosTfMessage(b, m.size); });
    });
  });
  fuzz::Accepts([&] {
    const RosbagSource source = RosbagSource::Open(path, RosbagOptions());
    PinholeCamera camera;
    camera.width = 4;
    camera.height = 3;
    if (source.camera_info()) {
      camera.width = static_cast<int>(source.camera_info()->width);
      camera.height = static_cast<int>(source.camera_info()->height);
    }
    for (size_t i = 0; i < source.size() && i < 4; ++i) {
      fuzz::Accepts([&] { source.Load(i, camera); });
    }
  });
  return 0;
}
