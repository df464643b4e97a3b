// The `detslam` command end to end: synth -> run -> report, and report's errors on bad input.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "support/cli_runner.h"

namespace detslam {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using testing::ReadFileBytes;
using testing::RunCli;

TEST(IntegrationReport, RunThenReportWithAccuracyAndPerFramePlots) {
  const fs::path dir = testing::TempDir("report");
  const fs::path seq = dir / "seq", out = dir / "out", log = dir / "log.txt";
  ASSERT_EQ(
      RunCli("synth --preset walking_xyz --seed 1 --frames 40 --out '" + seq.string() + "'", log),
      0)
      << ReadFileBytes(log);
  // The run's own settings keys (RunOptions, not SlamOptions) given with --set reach the run.
  ASSERT_EQ(RunCli("run --dataset '" + seq.string() + "' --segmenter gt --no-progress --out '" +
                       out.string() + "' --set Segmentation.CameraRateOpenCvThreads=3" +
                       " --set Segmentation.CameraRateFirstFrameWaits=true",
                   log),
            0)
      << ReadFileBytes(log);
  const std::string run_json = ReadFileBytes(out / "run.json");
  EXPECT_THAT(run_json, HasSubstr("\"Segmentation.CameraRateOpenCvThreads\": 3"));
  EXPECT_THAT(run_json, HasSubstr("\"Segmentation.CameraRateFirstFrameWaits\": true"));
  ASSERT_EQ(RunCli("report --run '" + out.string() + "'", log), 0) << ReadFileBytes(log);
  EXPECT_THAT(ReadFileBytes(log), HasSubstr("report: " + (out / "report.html").string()));
  const std::string html = ReadFileBytes(out / "report.html");
  EXPECT_THAT(html, HasSubstr("40 / 40 (100.0 %)"));
  EXPECT_THAT(html, HasSubstr("ATE (mm)"));  // ground truth found beside the run's dataset
  EXPECT_THAT(html, HasSubstr("(a) Top view"));
  EXPECT_THAT(html, HasSubstr("(b) Dynamic objects"));
  EXPECT_THAT(html, HasSubstr("segmenter</th><td>gt"));

  // Without ground truth (--no-eval) and to another file.
  ASSERT_EQ(RunCli("report --no-eval --run '" + out.string() + "' --out '" +
                       (dir / "r2.html").string() + "'",
                   log),
            0);
  EXPECT_THAT(ReadFileBytes(dir / "r2.html"), HasSubstr("No ground truth given"));

  // Bad input: a clear error naming the file, exit 1, no report written.
  EXPECT_EQ(RunCli("report --run '" + (dir / "nope").string() + "'", log), 1);
  EXPECT_THAT(ReadFileBytes(log),
              HasSubstr("error: " + (dir / "nope").string() + ": not a folder"));
  fs::create_directories(dir / "broken");
  std::ofstream(dir / "broken" / "run.json") << "{\"dataset\": 1}\n";
  EXPECT_EQ(RunCli("report --run '" + (dir / "broken").string() + "'", log), 1);
  EXPECT_THAT(ReadFileBytes(log), HasSubstr((dir / "broken" / "run.json").string() +
                                            ": key 'dataset' has the wrong type"));
  EXPECT_FALSE(fs::exists(dir / "broken" / "report.html"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace detslam
