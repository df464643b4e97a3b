// Faults in the middle of a run, as a user meets them with `detslam run`: each case either skips
// the frame with a warning listed in run.json or stops with a clear error naming the file; never a
// crash, a hang or a truncated output (README "Faults").
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <set>

#include "detslam/io/dataset.h"
#include "detslam/io/trajectory.h"
#include "detslam/synth/writer.h"
#include "integration_util.h"
#include "support/cli_runner.h"

namespace detslam {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using testing::ReadFileBytes;
using testing::RunCli;
using integration::RunJson;
using testing::TempDir;

// A static synthetic sequence of `frames` frames in a fresh folder.
std::string Sequence(const std::string& name, int frames, double cover_start_s = -1) {
  const std::string dir = TempDir(name);
  SynthOptions so;
  so.preset = "static";
  so.seed = 2;
  so.frames = frames;
  so.people = false;
  if (cover_start_s >= 0) {
    so.cover_start_s = cover_start_s;
    so.cover_seconds = 10.0 / 30.0;  // frames of black colour and no depth
  }
  integration::WriteTestSequence(so, dir);
  return dir;
}

TEST(IntegrationFaults, UnreadableFramesAreSkippedListedAndTheRunGoesOn) {
  const std::string seq = Sequence("faults_unreadable", 60);
  const RgbdDataset dataset = RgbdDataset::Open(seq, {});
  // Frame 20: a truncated colour PNG; 30: an 8-bit depth image; 40: depth of the wrong size.
  const std::string rgb20 = dataset.frame(20).rgb_path;
  const std::string png = ReadFileBytes(rgb20);
  std::ofstream(rgb20, std::ios::binary | std::ios::trunc) << png.substr(0, png.size() / 2);
  cv::imwrite(dataset.frame(30).depth_path, cv::Mat(480, 640, CV_8UC1, cv::Scalar(9)));
  cv::imwrite(dataset.frame(40).depth_path, cv::Mat(240, 320, CV_16UC1, cv::Scalar(9000)));
  for (const bool threaded : {false, true}) {
    SCOPED_TRACE(threaded ? "threaded" : "sequential");
    const fs::path out = TempDir("faults_unreadable_run"), log = out / "log.txt";
    ASSERT_EQ(RunCli("run --dataset '" + seq + "' --out '" + (out / "run").string() +
                         "' --segmenter none --no-progress" + (threaded ? " --threaded" : ""),
                     log),
              0)
        << ReadFileBytes(log);
    EXPECT_THAT(ReadFileBytes(log), HasSubstr("frame 20 skipped: " + rgb20));
    EXPECT_THAT(ReadFileBytes(log), HasSubstr("skipped 3 frames"));
    const nlohmann::json j = RunJson(out / "run");
    ASSERT_EQ(j["skipped_frames"].size(), 3u);
    EXPECT_EQ(j["skipped_frames"][0]["frame"], 20);
    EXPECT_EQ(j["skipped_frames"][1]["frame"], 30);
    EXPECT_THAT(j["skipped_frames"][1]["reason"].get<std::string>(),
                HasSubstr(dataset.frame(30).depth_path));
    EXPECT_EQ(j["skipped_frames"][2]["frame"], 40);
    EXPECT_EQ(j["frames"], 60);
    EXPECT_EQ(j["per_frame"][30]["state"], "skipped");
    // Every other frame is tracked; the skipped ones have no pose.
    EXPECT_EQ(j["frames_tracked"], 57);
    const Trajectory t = ReadTumTrajectory((out / "run" / "trajectory.txt").string());
    EXPECT_EQ(t.size(), 57u);
    std::set<int64_t> stamps;
    for (const StampedPose& p : t) stamps.insert(p.stamp.ns);
    for (const int k : {20, 30, 40}) EXPECT_EQ(stamps.count(dataset.frame(k).rgb_stamp.ns), 0u);
  }
}

TEST(IntegrationFaults, NoReadableFrameAtAllIsAnErrorWithNoOutputs) {
  const std::string seq = Sequence("faults_none_readable", 5);
  const RgbdDataset dataset = RgbdDataset::Open(seq, {});
  for (size_t k = 0; k < dataset.size(); ++k)
    cv::imwrite(dataset.frame(k).depth_path, cv::Mat(480, 640, CV_8UC3, cv::Scalar(1, 2, 3)));
  const fs::path out = TempDir("faults_none_readable_run"), log = out / "log.txt";
  EXPECT_EQ(RunCli("run --dataset '" + seq + "' --out '" + (out / "run").string() +
                       "' --segmenter none --no-progress",
                   log),
            1);
  EXPECT_THAT(ReadFileBytes(log), HasSubstr("no frame of"));
  EXPECT_THAT(ReadFileBytes(log), HasSubstr(dataset.frame(0).depth_path));
  EXPECT_FALSE(fs::exists(out / "run" / "trajectory.txt"));
}

TEST(IntegrationFaults, AListedFileThatIsMissingStopsBeforeTheFirstFrame) {
  const std::string seq = Sequence("faults_missing", 5);
  const RgbdDataset dataset = RgbdDataset::Open(seq, {});
  fs::remove(dataset.frame(3).rgb_path);
  const fs::path out = TempDir("faults_missing_run"), log = out / "log.txt";
  EXPECT_EQ(RunCli("run --dataset '" + seq + "' --out '" + (out / "run").string() +
                       "' --segmenter none --no-progress",
                   log),
            1);
  EXPECT_THAT(ReadFileBytes(log), HasSubstr((fs::path(seq) / "rgb.txt").string() + ":"));
  EXPECT_THAT(ReadFileBytes(log), HasSubstr(fs::path(dataset.frame(3).rgb_path).filename().string()));
}

// Black, saturated and depth-less frames are input a sensor really delivers: processed (no pose
// where nothing can be seen), never a crash, and tracking carries on after them.
TEST(IntegrationFaults, BlackSaturatedAndDepthlessFramesDoNotStopTheRun) {
  const std::string seq = Sequence("faults_blank", 90, /*cover_start_s=*/1.0);  // 30-39 black
  const RgbdDataset dataset = RgbdDataset::Open(seq, {});
  for (size_t k = 50; k < 55; ++k)
    cv::imwrite(dataset.frame(k).rgb_path, cv::Mat(480, 640, CV_8UC3, cv::Scalar::all(255)));
  for (size_t k = 60; k < 65; ++k)
    cv::imwrite(dataset.frame(k).depth_path, cv::Mat(480, 640, CV_16UC1, cv::Scalar(0)));
  const fs::path out = TempDir("faults_blank_run"), log = out / "log.txt";
  ASSERT_EQ(RunCli("run --dataset '" + seq + "' --out '" + (out / "run").string() +
                       "' --segmenter none --no-progress",
                   log),
            0)
      << ReadFileBytes(log);
  const nlohmann::json j = RunJson(out / "run");
  EXPECT_EQ(j["frames"], 90);
  EXPECT_EQ(j["skipped_frames"].size(), 0u);
  for (int k = 30; k < 40; ++k) EXPECT_FALSE(j["per_frame"][k]["tracked"].get<bool>()) << k;
  for (int k = 70; k < 90; ++k) EXPECT_TRUE(j["per_frame"][k]["tracked"].get<bool>()) << k;
}

TEST(IntegrationFaults, AnOutputFolderThatCannotBeWrittenStopsBeforeTheFirstFrame) {
  const std::string seq = Sequence("faults_unwritable", 5);
  const fs::path dir = TempDir("faults_unwritable_run"), log = dir / "log.txt";
  std::ofstream(dir / "a_file") << "not a folder\n";
  // A folder under a regular file cannot be created, whatever the user's rights (tests run as
  // root in CI, where permission bits would not stop a write).
  EXPECT_EQ(RunCli("run --dataset '" + seq + "' --out '" + (dir / "a_file" / "out").string() +
                       "' --segmenter none",
                   log),
            1);
  EXPECT_THAT(ReadFileBytes(log), HasSubstr((dir / "a_file" / "out").string()));
  EXPECT_THAT(ReadFileBytes(log), HasSubstr("output folder"));
  EXPECT_THAT(ReadFileBytes(log), ::testing::Not(HasSubstr("[run]")));  // no frame processed
  EXPECT_EQ(RunCli("run --dataset '" + seq + "' --out '" + (dir / "out").string() +
                       "' --segmenter none --save-map '" + (dir / "a_file" / "m.dslmap").string() +
                       "'",
                   log),
            1);
  EXPECT_THAT(ReadFileBytes(log), HasSubstr("--save-map"));
}

// The disk fills up while the outputs are written (a file size limit stands in for it): the run
// fails with a clear error, and every output file is either the previous run's or the new one,
// whole.
TEST(IntegrationFaults, AFullDiskLeavesThePreviousOutputsWhole) {
  const std::string seq = Sequence("faults_full", 60);
  const fs::path dir = TempDir("faults_full_run"), log = dir / "log.txt", out = dir / "out";
  const std::string run = std::string(DETSLAM_CLI_PATH) + " run --dataset '" + seq + "' --out '" +
                          out.string() + "' --segmenter none --no-progress";
  ASSERT_EQ(std::system((run + " > '" + log.string() + "' 2>&1").c_str()), 0) << ReadFileBytes(log);
  const std::string old_json = ReadFileBytes(out / "run.json");
  ASSERT_GT(old_json.size(), 16u * 1024);
  // 16 KiB per file at most: the new trajectory (40 lines) fits, run.json does not.
  const int status = std::system(
      ("bash -c \"ulimit -f 16; " + run + " --max-frames 40\" > '" + log.string() + "' 2>&1").c_str());
  EXPECT_NE(status, 0);
  EXPECT_THAT(ReadFileBytes(log), HasSubstr("run.json"));
  EXPECT_THAT(ReadFileBytes(log), HasSubstr("disk full?"));
  EXPECT_EQ(ReadFileBytes(out / "run.json"), old_json);  // the previous one, whole
  const Trajectory t = ReadTumTrajectory((out / "trajectory.txt").string());
  EXPECT_TRUE(t.size() == 40u || t.size() == 60u) << t.size();
}

}  // namespace
}  // namespace detslam
