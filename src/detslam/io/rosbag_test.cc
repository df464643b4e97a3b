#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <spdlog/spdlog.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "detslam/core/check.h"
#include "detslam/io/ros_messages.h"
#include "detslam/io/rosbag_file.h"
#include "detslam/io/rosbag_source.h"
#include "support/bag_writer.h"
#include "support/cli_runner.h"

namespace detslam {
namespace rosbag_test {
namespace {
namespace fs = std::filesystem;
using ::testing::HasSubstr;
using testing::BagWriter;

constexpr int kWidth = 8, kHeight = 6;
const std::string kRgb = "/camera/rgb/image_color", kDepth = "/camera/depth/image",
                  kInfo = "/camera/rgb/camera_info";

Timestamp Stamp(double s) { return Timestamp::FromSeconds(s); }

// Colour frame i: a gradient that differs per frame and per channel (BGR).
cv::Mat Colour(int i) {
  cv::Mat m(kHeight, kWidth, CV_8UC3);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) m.at<cv::Vec3b>(y, x) = cv::Vec3b(10 * x + i, 20 * y, 7 * i + 1);
  return m;
}
// Depth frame i in metres: 1 + x/10 + y/100 + i/1000, one missing pixel.
cv::Mat DepthMetres(int i) {
  cv::Mat m(kHeight, kWidth, CV_32FC1);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) m.at<float>(y, x) = 1.0f + 0.1f * x + 0.01f * y + 0.001f * i;
  m.at<float>(0, 0) = 0;
  return m;
}

// A bag of `frames` colour (rgb8) and 32FC1 depth frames at 30 Hz, depth 5 ms after colour.
std::vector<uint8_t> MakeBag(RosbagCompression c, int frames, bool index = true,
                             size_t chunk_bytes = 1 << 20) {
  BagWriter w(c, chunk_bytes);
  const uint32_t info = w.AddConnection(kInfo, "sensor_msgs/CameraInfo");
  const uint32_t rgb = w.AddConnection(kRgb, "sensor_msgs/Image");
  const uint32_t depth = w.AddConnection(kDepth, "sensor_msgs/Image");
  w.Write(info, Stamp(10), testing::CameraInfoMessage(Stamp(10), kWidth, kHeight, 500, 501, 3.5, 2.5));
  for (int i = 0; i < frames; ++i) {
    const Timestamp t = Stamp(10 + i / 30.0);
    cv::Mat rgb8;
    cv::cvtColor(Colour(i), rgb8, cv::COLOR_BGR2RGB);
    w.Write(rgb, t, testing::ImageMessage(t, rgb8, "rgb8"));
    const Timestamp td = Stamp(10.005 + i / 30.0);
    w.Write(depth, td, testing::ImageMessage(td, DepthMetres(i), "32FC1"));
  }
  return w.Finish(index);
}

PinholeCamera Camera() {
  PinholeCamera c;
  c.width = kWidth;
  c.height = kHeight;
  return c;
}

void ExpectFrame(const RgbdSource& s, size_t i, int frame) {
  const RgbdImages im = s.Load(i, Camera());
  EXPECT_EQ(cv::norm(im.bgr, Colour(frame), cv::NORM_INF), 0) << "frame " << i;
  EXPECT_EQ(cv::norm(im.depth_m, DepthMetres(frame), cv::NORM_INF), 0) << "frame " << i;
  EXPECT_EQ(im.gray.type(), CV_8UC1);
}

class RosbagCompressionTest : public ::testing::TestWithParam<RosbagCompression> {};

TEST_P(RosbagCompressionTest, ReadsFramesStampsAndCameraInfo) {
  // Small chunks: frames spread over many chunks, so Load reads across them.
  const std::string path = testing::WriteBagFile(MakeBag(GetParam(), 12, true, 600), "bag_ok.bag");
  const RosbagSource s = RosbagSource::Open(path, RosbagOptions());
  ASSERT_EQ(s.size(), 12u);
  EXPECT_EQ(s.rgb_messages(), 12u);
  EXPECT_EQ(s.depth_messages(), 12u);
  for (size_t i = 0; i < s.size(); ++i) {
    EXPECT_EQ(s.stamp(i), Stamp(10 + i / 30.0));
    EXPECT_EQ(s.depth_stamp(i), Stamp(10.005 + i / 30.0));
  }
  ExpectFrame(s, 0, 0);
  ExpectFrame(s, 11, 11);
  ExpectFrame(s, 5, 5);  // backwards: the chunk cache is replaced
  ASSERT_TRUE(s.camera_info().has_value());
  EXPECT_EQ(s.camera_info()->width, 8u);
  EXPECT_DOUBLE_EQ(s.camera_info()->k[0], 500);
  EXPECT_DOUBLE_EQ(s.camera_info()->k[4], 501);
  const Settings settings = SettingsForBag(path, s.camera_info());
  EXPECT_EQ(settings.camera.width, kWidth);
  EXPECT_DOUBLE_EQ(settings.camera.fy, 501);
  EXPECT_DOUBLE_EQ(settings.camera.cx, 3.5);
  EXPECT_THAT(settings.source, HasSubstr("camera info"));
}

INSTANTIATE_TEST_SUITE_P(All, RosbagCompressionTest,
                         ::testing::Values(RosbagCompression::kNone, RosbagCompression::kBz2,
                                           RosbagCompression::kLz4));

TEST(RosbagSource, PresetFromTheFileNameWinsOverCameraInfo) {
  const std::string path = testing::WriteBagFile(MakeBag(RosbagCompression::kNone, 2),
                                    "rgbd_dataset_freiburg1_xyz.bag");
  const RosbagSource s = RosbagSource::Open(path, RosbagOptions());
  EXPECT_EQ(SettingsForBag(path, s.camera_info()).source, "preset fr1");
  EXPECT_THROW(SettingsForBag(testing::TempPath("unnamed.bag"), std::nullopt), InputError);
}

TEST(RosbagSource, DepthEncodingsStepPaddingAndByteOrder) {
  BagWriter w;
  const uint32_t rgb = w.AddConnection(kRgb, "sensor_msgs/Image");
  const uint32_t depth = w.AddConnection(kDepth, "sensor_msgs/Image");
  cv::Mat mm(kHeight, kWidth, CV_16UC1);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) mm.at<uint16_t>(y, x) = static_cast<uint16_t>(1000 + 300 * x + y);
  cv::Mat gray(kHeight, kWidth, CV_8UC1, cv::Scalar(77));
  cv::Mat nan_depth = DepthMetres(0);
  nan_depth.at<float>(1, 1) = std::numeric_limits<float>::quiet_NaN();
  nan_depth.at<float>(1, 2) = -1;
  // Frame 0: bgr8 colour with padded rows, 16UC1 depth big-endian. Frame 1: mono8, 32FC1 with NaN.
  w.Write(rgb, Stamp(1), testing::ImageMessage(Stamp(1), Colour(3), "bgr8", kWidth * 3 + 5));
  w.Write(depth, Stamp(1), testing::ImageMessage(Stamp(1), mm, "16UC1", 0, true));
  w.Write(rgb, Stamp(2), testing::ImageMessage(Stamp(2), gray, "mono8"));
  w.Write(depth, Stamp(2), testing::ImageMessage(Stamp(2), nan_depth, "32FC1", kWidth * 4 + 4));
  const std::string path = testing::WriteBagFile(w.Finish(), "bag_encodings.bag");
  const RosbagSource s = RosbagSource::Open(path, RosbagOptions());
  ASSERT_EQ(s.size(), 2u);
  const RgbdImages a = s.Load(0, Camera());
  EXPECT_EQ(cv::norm(a.bgr, Colour(3), cv::NORM_INF), 0);
  cv::Mat expected;
  mm.convertTo(expected, CV_32F, 0.001);
  EXPECT_LT(cv::norm(a.depth_m, expected, cv::NORM_INF), 1e-6);
  const RgbdImages b = s.Load(1, Camera());
  EXPECT_EQ(b.bgr.at<cv::Vec3b>(2, 2), cv::Vec3b(77, 77, 77));
  EXPECT_EQ(b.depth_m.at<float>(1, 1), 0.0f);  // NaN: missing
  EXPECT_EQ(b.depth_m.at<float>(1, 2), 0.0f);  // negative: missing
  EXPECT_EQ(b.depth_m.at<float>(3, 3), nan_depth.at<float>(3, 3));
}

TEST(RosbagSource, CompressedColourAndDepth) {
  BagWriter w;
  const uint32_t rgb = w.AddConnection(kRgb, "sensor_msgs/CompressedImage");
  const uint32_t depth = w.AddConnection(kDepth, "sensor_msgs/CompressedImage");
  cv::Mat mm(kHeight, kWidth, CV_16UC1);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) mm.at<uint16_t>(y, x) = static_cast<uint16_t>(900 + 250 * x + 3 * y);
  mm.at<uint16_t>(0, 0) = 0;
  std::vector<uint8_t> png, depth_png;
  cv::imencode(".png", Colour(4), png);
  cv::imencode(".png", mm, depth_png);
  // compressedDepth: int32 format, float depthQuantA, depthQuantB, then the PNG.
  const auto compressed_depth = [](const std::vector<uint8_t>& encoded, float a, float b) {
    testing::Bytes h;
    h.U32(0);
    h.Raw(&a, 4).Raw(&b, 4).Raw(encoded);
    return h.bytes();
  };
  w.Write(rgb, Stamp(1), testing::CompressedImageMessage(Stamp(1), "rgb8; png compressed bgr8", png));
  w.Write(depth, Stamp(1), testing::CompressedImageMessage(Stamp(1), "16UC1; compressedDepth png",
                                                           compressed_depth(depth_png, 0, 0)));
  // 32FC1 as image_transport quantises it: v = A / depth + B (A = z0 (z0 + 1), B = 1 - A / max).
  const float a = 100.0f * 101.0f, b = 1.0f - a / 10.0f;
  cv::Mat inverse(kHeight, kWidth, CV_16UC1);
  const cv::Mat metres = DepthMetres(2);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const float d = metres.at<float>(y, x);
      inverse.at<uint16_t>(y, x) = d > 0 ? static_cast<uint16_t>(std::lround(a / d + b)) : 0;
    }
  std::vector<uint8_t> inverse_png, jpeg;
  cv::imencode(".png", inverse, inverse_png);
  cv::imencode(".jpg", Colour(5), jpeg, {cv::IMWRITE_JPEG_QUALITY, 100});
  w.Write(rgb, Stamp(2), testing::CompressedImageMessage(Stamp(2), "jpeg", jpeg));
  w.Write(depth, Stamp(2), testing::CompressedImageMessage(Stamp(2), "32FC1; compressedDepth png",
                                                           compressed_depth(inverse_png, a, b)));
  const RosbagSource s = RosbagSource::Open(testing::WriteBagFile(w.Finish(), "bag_compressed.bag"), {});
  ASSERT_EQ(s.size(), 2u);
  const RgbdImages png_frame = s.Load(0, Camera());
  EXPECT_EQ(cv::norm(png_frame.bgr, Colour(4), cv::NORM_INF), 0);  // PNG: lossless
  cv::Mat expected;
  mm.convertTo(expected, CV_32F, 0.001);
  EXPECT_LT(cv::norm(png_frame.depth_m, expected, cv::NORM_INF), 1e-6);
  const RgbdImages jpeg_frame = s.Load(1, Camera());
  EXPECT_LT(cv::norm(jpeg_frame.bgr, Colour(5), cv::NORM_L1) / (kWidth * kHeight * 3), 4.0);
  EXPECT_EQ(jpeg_frame.depth_m.at<float>(0, 0), 0.0f);  // missing stays missing
  // Quantisation step at depth d: d^2 / A (under 0.3 mm at 1.8 m here).
  EXPECT_LT(cv::norm(jpeg_frame.depth_m, metres, cv::NORM_INF), 5e-4);

  // Formats that are not read: a clear error naming topic and stamp.
  BagWriter bad;
  const uint32_t r2 = bad.AddConnection(kRgb, "sensor_msgs/CompressedImage");
  const uint32_t d2 = bad.AddConnection(kDepth, "sensor_msgs/CompressedImage");
  bad.Write(r2, Stamp(1), testing::CompressedImageMessage(Stamp(1), "png", png));
  bad.Write(d2, Stamp(1), testing::CompressedImageMessage(Stamp(1), "png", depth_png));
  const RosbagSource b2 = RosbagSource::Open(testing::WriteBagFile(bad.Finish(), "bag_bad_depth.bag"), {});
  try {
    b2.Load(0, Camera());
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("compressed depth format 'png' is not read"));
    EXPECT_THAT(e.what(), HasSubstr("topic " + kDepth));
  }
}

TEST(RosbagSource, UnsortedMessagesAreOrderedByHeaderStamp) {
  BagWriter w;
  const uint32_t rgb = w.AddConnection(kRgb, "sensor_msgs/Image");
  const uint32_t depth = w.AddConnection(kDepth, "sensor_msgs/Image");
  for (int i : {2, 0, 1}) {
    cv::Mat rgb8;
    cv::cvtColor(Colour(i), rgb8, cv::COLOR_BGR2RGB);
    w.Write(rgb, Stamp(50), testing::ImageMessage(Stamp(1 + i), rgb8, "rgb8"));
    w.Write(depth, Stamp(50), testing::ImageMessage(Stamp(1 + i), DepthMetres(i), "32FC1"));
  }
  const RosbagSource s = RosbagSource::Open(testing::WriteBagFile(w.Finish(), "bag_unsorted.bag"), {});
  ASSERT_EQ(s.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(s.stamp(i), Stamp(1 + i));
    ExpectFrame(s, i, i);
  }
}

TEST(RosbagSource, ClearErrors) {
  const auto open_error = [](const std::string& path, const RosbagOptions& o = {}) {
    try {
      RosbagSource::Open(path, o);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string ok = testing::WriteBagFile(MakeBag(RosbagCompression::kNone, 3), "bag_errors.bag");
  RosbagOptions other;
  other.rgb_topic = "/nope";
  EXPECT_THAT(open_error(ok, other), HasSubstr("no topic /nope"));
  EXPECT_THAT(open_error(ok, other), HasSubstr(kRgb + " (sensor_msgs/Image)"));
  other = RosbagOptions();
  other.depth_topic = kInfo;
  EXPECT_THAT(open_error(ok, other), HasSubstr("carries sensor_msgs/CameraInfo"));
  other = RosbagOptions();
  other.offset_s = 10;
  EXPECT_THAT(open_error(ok, other), HasSubstr("no colour image"));
  EXPECT_THAT(open_error(testing::TempPath("missing.bag")), HasSubstr("does not exist"));

  std::ofstream(testing::TempPath("text.bag")) << "hello\n";
  EXPECT_THAT(open_error(testing::TempPath("text.bag")), HasSubstr("not a ROS bag"));
  std::ofstream(testing::TempPath("v12.bag")) << "#ROSBAG V1.2\nxxxxx";
  EXPECT_THAT(open_error(testing::TempPath("v12.bag")), HasSubstr("version '1.2'"));

  // A colour encoding detslam does not read: the frame fails to load, naming topic and stamp.
  BagWriter w;
  const uint32_t rgb = w.AddConnection(kRgb, "sensor_msgs/Image");
  const uint32_t depth = w.AddConnection(kDepth, "sensor_msgs/Image");
  w.Write(rgb, Stamp(1), testing::ImageMessage(Stamp(1), Colour(0), "yuv422"));
  w.Write(depth, Stamp(1), testing::ImageMessage(Stamp(1), DepthMetres(0), "32FC1"));
  const RosbagSource s = RosbagSource::Open(testing::WriteBagFile(w.Finish(), "bag_yuv.bag"), {});
  try {
    s.Load(0, Camera());
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("colour encoding 'yuv422'"));
    EXPECT_THAT(e.what(), HasSubstr("topic " + kRgb + ", message stamped 1.000000"));
  }
  PinholeCamera wrong = Camera();
  wrong.width = 640;
  const RosbagSource good = RosbagSource::Open(ok, {});
  EXPECT_THROW(good.Load(0, wrong), InputError);
}

TEST(RosbagFile, CutOffRecordingReadsTheCompleteChunks) {
  const std::vector<uint8_t> full = MakeBag(RosbagCompression::kLz4, 20, false, 400);
  const RosbagFile whole = RosbagFile::Open(testing::WriteBagFile(full, "bag_whole.bag"));
  EXPECT_FALSE(whole.indexed());
  EXPECT_TRUE(whole.truncation().empty());
  ASSERT_GT(whole.chunks().size(), 4u);
  // Cut inside the fourth chunk's data: the three before it stay readable.
  const size_t cut = whole.chunks()[3].data_pos + whole.chunks()[3].data_size / 2;
  const std::vector<uint8_t> head(full.begin(), full.begin() + static_cast<long>(cut));
  const std::string path = testing::WriteBagFile(head, "bag_cut.bag");
  const RosbagFile bag = RosbagFile::Open(path);
  EXPECT_EQ(bag.chunks().size(), 3u);
  EXPECT_THAT(bag.truncation(), HasSubstr("recording cut off"));
  EXPECT_LT(bag.messages().size(), whole.messages().size());
  const RosbagSource s = RosbagSource::Open(path, {});
  EXPECT_GT(s.size(), 0u);
  ExpectFrame(s, s.size() - 1, static_cast<int>(s.size()) - 1);
  // Every cut position gives a clean result or an InputError, never a crash.
  const spdlog::level::level_enum level = spdlog::get_level();
  spdlog::set_level(spdlog::level::err);
  for (size_t n = 0; n < full.size(); n += 97) {
    const std::string p = testing::WriteBagFile(std::vector<uint8_t>(full.begin(), full.begin() + static_cast<long>(n)),
                                   "bag_cut_n.bag");
    try {
      RosbagFile::Open(p);
    } catch (const InputError&) {
    }
  }
  spdlog::set_level(level);
}

TEST(RosbagFile, CorruptChunksAndRecordsAreInputErrors) {
  const std::vector<uint8_t> good = MakeBag(RosbagCompression::kBz2, 3);
  const RosbagFile bag = RosbagFile::Open(testing::WriteBagFile(good, "bag_bz2.bag"));
  ASSERT_EQ(bag.chunks().size(), 1u);
  std::vector<uint8_t> bad = good;
  bad[bag.chunks()[0].data_pos + bag.chunks()[0].data_size / 2] ^= 0x5a;
  try {
    RosbagFile::Open(testing::WriteBagFile(bad, "bag_bz2_bad.bag"));
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("bz2 chunk"));
    EXPECT_THAT(e.what(), HasSubstr("at byte"));
  }
  EXPECT_THROW(DecompressRosbagChunk(RosbagCompression::kLz4, good.data(), 40, 100),
               std::runtime_error);
  EXPECT_THROW(DecompressRosbagChunk(RosbagCompression::kNone, good.data(), 40, 100),
               std::runtime_error);
  // An unknown compression name.
  std::string text(good.begin(), good.end());
  const size_t at = text.find("compression=bz2");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 15, "compression=zzz");
  try {
    RosbagFile::Open(testing::WriteBagFile(std::vector<uint8_t>(text.begin(), text.end()), "bag_zzz.bag"));
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("unknown chunk compression 'zzz'"));
  }
}

TEST(RosMessages, ParseErrorsNameTheField) {
  const std::vector<uint8_t> im = testing::ImageMessage(Stamp(3.25), Colour(0), "bgr8");
  const RosImage parsed = ParseRosImage(im.data(), im.size());
  EXPECT_EQ(parsed.header.stamp, Stamp(3.25));
  EXPECT_EQ(parsed.header.frame_id, "camera");
  EXPECT_EQ(parsed.step, static_cast<uint32_t>(kWidth * 3));
  try {
    ParseRosImage(im.data(), im.size() - 1);
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("field 'data'"));
  }
  std::vector<uint8_t> longer = im;
  longer.push_back(0);
  EXPECT_THROW(ParseRosImage(longer.data(), longer.size()), std::runtime_error);
  const std::vector<uint8_t> info = testing::CameraInfoMessage(Stamp(1), 640, 480, 525, 525, 319.5, 239.5);
  EXPECT_DOUBLE_EQ(ParseRosCameraInfo(info.data(), info.size()).k[2], 319.5);
  EXPECT_THROW(ParseRosCameraInfo(im.data(), im.size()), std::runtime_error);
  testing::Bytes tf;
  tf.U32(1).U32(7).Time(Stamp(2)).String("world").String("kinect");
  for (double v : {1.0, 2.0, 3.0, 0.0, 0.0, 0.0, 1.0}) tf.F64(v);
  const std::vector<RosTransform> t = ParseRosTfMessage(tf.bytes().data(), tf.size());
  ASSERT_EQ(t.size(), 1u);
  EXPECT_EQ(t[0].header.frame_id, "world");
  EXPECT_EQ(t[0].child_frame_id, "kinect");
  EXPECT_DOUBLE_EQ(t[0].translation[2], 3.0);
  EXPECT_DOUBLE_EQ(t[0].rotation[3], 1.0);
}

}  // namespace
}  // namespace rosbag_test
}  // namespace detslam
