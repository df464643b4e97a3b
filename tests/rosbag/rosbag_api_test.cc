// Bags written by ROS's own rosbag C++ API (librosbag-storage-dev), read by detslam's reader:
// a synthetic sequence as a bag in the layouts users record (32FC1 metres or 16UC1 millimetres,
// chunks uncompressed, bz2 or lz4) gives the trajectory of the folder run.
#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <tf2_msgs/TFMessage.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "detslam/eval/evaluate.h"
#include "detslam/io/dataset.h"
#include "detslam/io/rosbag_source.h"
#include "detslam/io/settings.h"
#include "detslam/io/trajectory.h"
#include "detslam/pipeline/runner.h"
#include "detslam/synth/writer.h"
#include "integration_util.h"
#include "support/cli_runner.h"
#include "support/ros_test_bag.h"

namespace detslam {
namespace {
namespace fs = std::filesystem;
using testing::DepthEncoding;
using testing::WriteSequenceBag;

constexpr int kFrames = 40;

// trajectory.txt without its first line (which names the input).
std::string Poses(const fs::path& out) {
  std::ifstream in(out / "trajectory.txt");
  std::string first, rest;
  std::getline(in, first);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

class IntegrationRosbagApi : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = integration::WritePresetSequence("rosbag_api_seq", "walking_xyz", 3, kFrames);
    settings_ = ReadSettings((fs::path(dir_) / "settings.yaml").string());
    folder_out_ = testing::TempDir("rosbag_api_folder_out");
    RunOptions options;
    options.out_dir = folder_out_;
    options.slam = SlamOptionsFromSettings(settings_, 7);
    detslam::Run(RgbdDataset::Open(dir_, {}), settings_, options);
  }
  // Runs sequential SLAM (no segmenter) on the bag; returns the output folder.
  static std::string RunBag(const std::string& bag, const std::string& name) {
    const std::string out = testing::TempDir(name);
    RunOptions options;
    options.out_dir = out;
    options.slam = SlamOptionsFromSettings(settings_, 7);
    const RunSummary s = detslam::Run(RosbagSource::Open(bag, {}), settings_, options);
    EXPECT_EQ(s.frames, static_cast<size_t>(kFrames));
    EXPECT_EQ(s.skipped, 0u);
    return out;
  }
  static std::string dir_, folder_out_;
  static Settings settings_;
};
std::string IntegrationRosbagApi::dir_, IntegrationRosbagApi::folder_out_;
Settings IntegrationRosbagApi::settings_;

TEST_F(IntegrationRosbagApi, MetresDepthGivesTheFolderTrajectoryWithEveryCompression) {
  const std::string folder = Poses(folder_out_);
  ASSERT_FALSE(folder.empty());
  const std::pair<uint32_t, const char*> kinds[] = {{rosbag::compression::Uncompressed, "none"},
                                                    {rosbag::compression::BZ2, "bz2"},
                                                    {rosbag::compression::LZ4, "lz4"}};
  for (const auto& [compression, name] : kinds) {
    SCOPED_TRACE(name);
    const std::string bag = testing::TempPath(std::string("api_32f_") + name + ".bag");
    WriteSequenceBag(dir_, bag, compression, DepthEncoding::kMetres32F);
    const RosbagSource source = RosbagSource::Open(bag, {});
    ASSERT_EQ(source.size(), static_cast<size_t>(kFrames));
    const RgbdDataset folder_ds = RgbdDataset::Open(dir_, {});
    // Every frame decodes to the folder's images bit for bit, so a deterministic run gives the
    // folder's trajectory: run on one of them (bz2; the command-line test runs an lz4 bag).
    for (size_t i = 0; i < source.size(); ++i) {
      EXPECT_EQ(source.stamp(i), folder_ds.frame(i).rgb_stamp);
      const RgbdImages a = source.Load(i, settings_.camera);
      const RgbdImages b = folder_ds.Load(i, settings_.camera);
      EXPECT_EQ(cv::norm(a.bgr, b.bgr, cv::NORM_INF), 0) << "frame " << i;
      EXPECT_EQ(cv::norm(a.depth_m, b.depth_m, cv::NORM_INF), 0) << "frame " << i;
    }
    if (compression == rosbag::compression::BZ2) {
      EXPECT_EQ(Poses(RunBag(bag, std::string("rosbag_api_out_") + name)), folder);
    }
  }
}

TEST_F(IntegrationRosbagApi, MillimetreDepthTracksAsAccuratelyAsTheFolder) {
  const std::string bag = testing::TempPath("api_16u_bz2.bag");
  WriteSequenceBag(dir_, bag, rosbag::compression::BZ2, DepthEncoding::kMillimetres16U);
  const std::string out = RunBag(bag, "rosbag_api_out_16u");
  const std::string gt = (fs::path(dir_) / "groundtruth.txt").string();
  const EvalResult folder =
      EvaluateFiles(gt, (fs::path(folder_out_) / "trajectory.txt").string(), dir_, {});
  const EvalResult mm = EvaluateFiles(gt, (fs::path(out) / "trajectory.txt").string(), dir_, {});
  EXPECT_EQ(mm.coverage.fraction, 1.0);
  // Depth rounded to 1 mm instead of 0.2 mm changes the numbers, not the accuracy class.
  EXPECT_LT(mm.ate.error_m.rmse, 1.5 * folder.ate.error_m.rmse + 0.002)
      << "folder " << folder.ate.error_m.rmse << " m, 16UC1 bag " << mm.ate.error_m.rmse << " m";
}

TEST_F(IntegrationRosbagApi, CommandLineReadsTheBag) {
  const std::string bag = testing::TempPath("api_cli_lz4.bag");
  WriteSequenceBag(dir_, bag, rosbag::compression::LZ4, DepthEncoding::kMetres32F);
  const std::string out = testing::TempDir("rosbag_api_cli_out");
  const fs::path log = fs::path(out) / "log.txt";
  const std::string config = (fs::path(dir_) / "settings.yaml").string();
  ASSERT_EQ(testing::RunCli("run --rosbag " + bag + " --config " + config + " --out " + out +
                                " --segmenter none --no-progress --seed 7",
                            log),
            0)
      << testing::ReadFileBytes(log);
  EXPECT_EQ(Poses(out), Poses(folder_out_));
  // Without --config the camera comes from the bag's camera info (the rest from the defaults).
  ASSERT_EQ(testing::RunCli("run --rosbag " + bag + " --out " + out +
                                " --segmenter none --no-progress --seed 7",
                            log),
            0)
      << testing::ReadFileBytes(log);
  const std::string text = testing::ReadFileBytes(log);
  EXPECT_NE(text.find("settings: camera info in"), std::string::npos) << text;
  const std::string all = "tracked " + std::to_string(kFrames) + "/" + std::to_string(kFrames) + " frames";
  EXPECT_NE(text.find(all), std::string::npos) << text;
  // Ground truth from the bag's tf: the folder's groundtruth.txt again.
  const std::string gt = (fs::path(out) / "gt_from_tf.txt").string();
  ASSERT_EQ(testing::RunCli("rosbag groundtruth " + bag + " --out " + gt, log), 0)
      << testing::ReadFileBytes(log);
  const Trajectory from_tf = ReadTumTrajectory(gt);
  const Trajectory truth = ReadTumTrajectory((fs::path(dir_) / "groundtruth.txt").string());
  ASSERT_EQ(from_tf.size(), truth.size());
  for (size_t i = 0; i < truth.size(); ++i) {
    EXPECT_EQ(from_tf[i].stamp, truth[i].stamp);
    EXPECT_LT((from_tf[i].world_from_cam.translation() - truth[i].world_from_cam.translation()).norm(), 1e-8);
    EXPECT_LT(from_tf[i].world_from_cam.rotation().angularDistance(truth[i].world_from_cam.rotation()), 1e-8);
  }
  ASSERT_EQ(testing::RunCli("rosbag info " + bag, log), 0);
  EXPECT_NE(testing::ReadFileBytes(log).find("/tf_static"), std::string::npos) << testing::ReadFileBytes(log);
  // Errors name the problem and exit non-zero.
  EXPECT_NE(testing::RunCli("run --rosbag " + bag + " --rgb-topic /camera/rgb/image --out " + out,
                            log),
            0);
  EXPECT_NE(testing::ReadFileBytes(log).find("no topic /camera/rgb/image"), std::string::npos)
      << testing::ReadFileBytes(log);
}

}  // namespace
}  // namespace detslam
