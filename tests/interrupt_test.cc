// Stopping a run early: RunOptions::stop (library) and SIGINT / SIGTERM on `detslam run` (command)
// end the run after the frame in progress with the outputs of the frames processed so far, marked
// interrupted; a second signal exits at once without leaving a truncated trajectory.
#include <gtest/gtest.h>

#include <atomic>
#include <csignal>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <thread>

#include "detslam/io/dataset.h"
#include "detslam/io/settings.h"
#include "detslam/io/trajectory.h"
#include "detslam/pipeline/runner.h"
#include "integration_util.h"
#include "support/cli_runner.h"

namespace detslam {
namespace {

namespace fs = std::filesystem;
using testing::ReadFileBytes;
using integration::RunJson;
using integration::WriteStaticSequence;
using testing::TempDir;

// One 200-frame sequence for the command tests (written once per test process).
const std::string& CommandSequence() {
  static const std::string dir = WriteStaticSequence("interrupt_cli", 1, 200);
  return dir;
}

// The outputs of an interrupted run agree with each other: run.json says interrupted and how many
// frames were processed, trajectory.txt holds exactly the tracked ones.
void ExpectInterruptedOutputs(const fs::path& out, size_t min_frames, size_t max_frames) {
  const nlohmann::json j = RunJson(out);
  EXPECT_TRUE(j["interrupted"].get<bool>());
  const size_t frames = j["frames"].get<size_t>();
  EXPECT_GE(frames, min_frames);
  EXPECT_LT(frames, max_frames);
  EXPECT_EQ(j["per_frame"].size(), frames);
  const Trajectory t = ReadTumTrajectory((out / "trajectory.txt").string());
  EXPECT_EQ(t.size(), j["frames_in_main_map"].get<size_t>());
  EXPECT_EQ(t.size(), j["frames_tracked"].get<size_t>());
  EXPECT_TRUE(fs::exists(out / "keyframes.txt"));
  EXPECT_TRUE(fs::exists(out / "map.ply"));
}

TEST(IntegrationInterrupt, AStopRequestEndsTheRunWithTheOutputsSoFar) {
  const std::string seq = WriteStaticSequence("interrupt_lib", 1, 60);
  const RgbdDataset dataset = RgbdDataset::Open(seq, {});
  const Settings settings = PresetForDataset(seq);
  for (const auto& [threaded, mapping_thread] :
       {std::pair{false, false}, {true, false}, {true, true}}) {
    SCOPED_TRACE(::testing::Message() << "threaded " << threaded << ", mapping thread " << mapping_thread);
    std::atomic<bool> stop{false};
    RunOptions options;
    options.out_dir = TempDir("interrupt_lib_run");
    options.threaded = threaded;
    options.mapping_thread = mapping_thread;
    options.slam = SlamOptionsFromSettings(settings, 42);
    options.stop = &stop;
    options.save_map = (fs::path(options.out_dir) / "map.dslmap").string();
    const RunSummary s = detslam::Run(
        dataset, settings, options,
        [&](size_t done, size_t, const FrameReport&) {
          if (done == 20) stop = true;
        },
        nullptr);
    EXPECT_TRUE(s.interrupted);
    if (!threaded) {
      EXPECT_EQ(s.frames, 20u);  // sequential: the frame in progress was the 20th
    }
    EXPECT_EQ(s.tracked, s.frames);
    ExpectInterruptedOutputs(options.out_dir, 20, 60);
    EXPECT_TRUE(fs::exists(options.save_map));
  }
  // Without a stop request the same run is complete and says so.
  std::atomic<bool> stop{false};
  RunOptions options;
  options.out_dir = TempDir("interrupt_lib_full");
  options.slam = SlamOptionsFromSettings(settings, 42);
  options.stop = &stop;
  const RunSummary s = detslam::Run(dataset, settings, options, nullptr, nullptr);
  EXPECT_FALSE(s.interrupted);
  EXPECT_EQ(s.frames, 60u);
  EXPECT_FALSE(RunJson(options.out_dir)["interrupted"].get<bool>());
}

// `detslam run` as a user stops it: Ctrl-C (SIGINT) or SIGTERM once it has processed 100 frames.
TEST(IntegrationInterrupt, SigintAndSigtermStopTheCommandWithItsOutputs) {
  const std::string& seq = CommandSequence();
  for (const auto& [sig, threaded] : {std::pair{SIGINT, false}, {SIGTERM, true}}) {
    SCOPED_TRACE(::testing::Message() << "signal " << sig << ", threaded " << threaded);
    const fs::path out = TempDir("interrupt_cli_run"), log = out / "log.txt";
    std::vector<std::string> args{"run", "--dataset", seq, "--out", (out / "run").string(),
                                  "--segmenter", "none"};
    if (threaded) args.push_back("--threaded");
    testing::ChildProcess run(DETSLAM_CLI_PATH, args, log);
    // Without a terminal the progress is a line every 100 frames.
    ASSERT_TRUE(run.WaitForLog("[run] 100/200", std::chrono::seconds(300))) << ReadFileBytes(log);
    run.Signal(sig);
    // A hang guard, not a timing: the stop itself takes well under a second (docs/RELIABILITY.md).
    EXPECT_EQ(run.Wait(std::chrono::seconds(30)), 128 + sig) << ReadFileBytes(log);
    EXPECT_NE(ReadFileBytes(log).find("interrupted after"), std::string::npos) << ReadFileBytes(log);
    ExpectInterruptedOutputs(out / "run", 100, 200);
  }
}

// A second signal quits at once. Whether the first one's outputs were already written or not,
// nothing is left half-written: trajectory.txt is absent or whole.
TEST(IntegrationInterrupt, ASecondSignalQuitsAtOnceWithoutTruncatedOutputs) {
  const std::string& seq = CommandSequence();
  const fs::path out = TempDir("interrupt_twice_run"), log = out / "log.txt";
  testing::ChildProcess run(DETSLAM_CLI_PATH,
                            {"run", "--dataset", seq, "--out", (out / "run").string(),
                             "--segmenter", "none", "--threaded"},
                            log);
  ASSERT_TRUE(run.WaitForLog("[run] 100/200", std::chrono::seconds(300))) << ReadFileBytes(log);
  run.Signal(SIGINT);
  ASSERT_TRUE(run.WaitForLog("again to quit at once", std::chrono::seconds(30)));
  run.Signal(SIGINT);
  EXPECT_EQ(run.Wait(std::chrono::seconds(30)), 128 + SIGINT) << ReadFileBytes(log);
  const fs::path trajectory = out / "run" / "trajectory.txt";
  if (fs::exists(trajectory)) {
    EXPECT_NO_THROW(ReadTumTrajectory(trajectory.string()));
  }
  if (fs::exists(out / "run" / "run.json")) {  // written last
    EXPECT_TRUE(RunJson(out / "run")["interrupted"].get<bool>());
  }
}

}  // namespace
}  // namespace detslam
