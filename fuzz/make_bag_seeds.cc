// Writes the seed bags of fuzz/corpus/rosbag (fuzz/make_corpus.sh runs it): two 4x3 frames with
// camera info, one bag per chunk compression, a cut-off unindexed one, and one with compressed
// image topics.
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "support/bag_writer.h"

int main(int argc, char** argv) {
  using namespace detslam;
  if (argc != 2) return 2;
  const std::string dir = argv[1];
  const std::pair<RosbagCompression, const char*> kinds[] = {
      {RosbagCompression::kNone, "none"}, {RosbagCompression::kBz2, "bz2"},
      {RosbagCompression::kLz4, "lz4"}};
  for (const auto& [compression, name] : kinds) {
    testing::BagWriter w(compression, 200);
    const uint32_t info = w.AddConnection("/camera/rgb/camera_info", "sensor_msgs/CameraInfo");
    const uint32_t rgb = w.AddConnection("/camera/rgb/image_color", "sensor_msgs/Image");
    const uint32_t depth = w.AddConnection("/camera/depth/image", "sensor_msgs/Image");
    const uint32_t tf = w.AddConnection("/tf", "tf2_msgs/TFMessage");
    w.Write(info, Timestamp{1000000000}, testing::CameraInfoMessage(Timestamp{1000000000}, 4, 3, 5, 5, 2, 1.5));
    for (int i = 0; i < 2; ++i) {
      const Timestamp t{1000000000 + i * 33333333};
      w.Write(rgb, t, testing::ImageMessage(t, cv::Mat(3, 4, CV_8UC3, cv::Scalar(i, 2, 3)), "rgb8"));
      w.Write(depth, t, testing::ImageMessage(t, cv::Mat(3, 4, i ? CV_16UC1 : CV_32FC1, cv::Scalar(1 + i)),
                                              i ? "16UC1" : "32FC1"));
      testing::Bytes m;
      m.U32(1).U32(0).Time(t).String("world").String("camera");
      for (double v : {0.1, 0.2, 0.3, 0.0, 0.0, 0.0, 1.0}) m.F64(v);
      w.Write(tf, t, m.bytes());
    }
    const bool cut = compression == RosbagCompression::kLz4;
    std::vector<uint8_t> bytes = w.Finish(!cut);
    if (cut) bytes.resize(bytes.size() - 20);
    std::ofstream(dir + "/" + name + (cut ? "_cut" : "") + ".bag", std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  }
  // Compressed topics: PNG colour, compressedDepth (16UC1 PNG behind its 12-byte header).
  testing::BagWriter w;
  const uint32_t rgb = w.AddConnection("/camera/rgb/image_color", "sensor_msgs/CompressedImage");
  const uint32_t depth = w.AddConnection("/camera/depth/image", "sensor_msgs/CompressedImage");
  std::vector<uint8_t> png, depth_png;
  cv::imencode(".png", cv::Mat(3, 4, CV_8UC3, cv::Scalar(1, 2, 3)), png);
  cv::imencode(".png", cv::Mat(3, 4, CV_16UC1, cv::Scalar(1500)), depth_png);
  testing::Bytes compressed_depth;
  compressed_depth.U32(0).U32(0).U32(0).Raw(depth_png);
  w.Write(rgb, Timestamp{1000000000}, testing::CompressedImageMessage(Timestamp{1000000000}, "png", png));
  w.Write(depth, Timestamp{1000000000},
          testing::CompressedImageMessage(Timestamp{1000000000}, "16UC1; compressedDepth png",
                                          compressed_depth.bytes()));
  const std::vector<uint8_t> bytes = w.Finish();
  std::ofstream(dir + "/compressed.bag", std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  return 0;
}
