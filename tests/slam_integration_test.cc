// Whole-pipeline tests: SLAM on real TUM data (../shared) and on synthetic sequences with ground
// truth, asserting tracked fraction and accuracy, and determinism of sequential runs.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "detslam/eval/evaluate.h"
#include "detslam/io/dataset.h"
#include "detslam/io/settings.h"
#include "detslam/pipeline/runner.h"
#include "detslam/synth/writer.h"
#include "support/shared_data.h"

namespace detslam {
namespace {

namespace fs = std::filesystem;

std::string TempDir(const std::string& name) {
  const fs::path p = fs::temp_directory_path() / ("detslam_it_" + name);
  fs::remove_all(p);
  fs::create_directories(p);
  return p.string();
}

struct SlamRun {
  RunSummary summary;
  EvalResult eval;
  std::string trajectory_path;
};

SlamRun RunAndEvaluate(const std::string& dataset_dir, const std::string& out_dir, uint64_t seed) {
  const RgbdDataset dataset = RgbdDataset::Open(dataset_dir, {});
  const Settings settings = PresetForDataset(dataset_dir);
  RunOptions options;
  options.out_dir = out_dir;
  options.slam = SlamOptionsFromSettings(settings, seed);
  SlamRun run;
  run.summary = RunSequential(dataset, settings, options);
  run.trajectory_path = (fs::path(out_dir) / "trajectory.txt").string();
  run.eval = EvaluateFiles(dataset.groundtruth_path(), run.trajectory_path, dataset_dir, {});
  return run;
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(DataSlamFr2Desk, TracksEveryFrameWithinFiveMillimetres) {
  DETSLAM_REQUIRE_SHARED("data/tum/rgbd_dataset_freiburg2_desk_subset50");
  const SlamRun run = RunAndEvaluate(testing::SharedPath("data/tum/rgbd_dataset_freiburg2_desk_subset50"),
                                     TempDir("fr2"), 42);
  EXPECT_EQ(run.summary.frames, 50u);
  EXPECT_EQ(run.summary.tracked, 50u);
  EXPECT_DOUBLE_EQ(run.eval.coverage.fraction, 1.0);
  EXPECT_LE(run.eval.ate.error_m.rmse, 0.005) << "ATE RMSE " << run.eval.ate.error_m.rmse;
  for (const char* f : {"trajectory.txt", "keyframes.txt", "map.ply", "run.json"}) {
    EXPECT_TRUE(fs::exists(fs::path(run.trajectory_path).parent_path() / f)) << f;
  }
}

TEST(DataSlamFr2Desk, SeededSequentialRunsAreIdentical) {
  DETSLAM_REQUIRE_SHARED("data/tum/rgbd_dataset_freiburg2_desk_subset50");
  const std::string dir = testing::SharedPath("data/tum/rgbd_dataset_freiburg2_desk_subset50");
  const SlamRun a = RunAndEvaluate(dir, TempDir("det_a"), 7);
  const SlamRun b = RunAndEvaluate(dir, TempDir("det_b"), 7);
  const std::string ta = ReadFile(a.trajectory_path), tb = ReadFile(b.trajectory_path);
  ASSERT_FALSE(ta.empty());
  // The header names the output folder; compare the pose lines.
  EXPECT_EQ(ta.substr(ta.find("\n1311")), tb.substr(tb.find("\n1311")));
}

TEST(IntegrationSlamSynthetic, StaticPresetTracksEveryFrameWithinOneCentimetre) {
  const std::string seq = TempDir("synth_static");
  SynthOptions so;
  so.preset = "static";
  so.seed = 3;
  so.frames = 240;
  WriteSequence(so, seq);
  const SlamRun run = RunAndEvaluate(seq, TempDir("synth_static_run"), 42);
  EXPECT_EQ(run.summary.tracked, run.summary.frames);
  EXPECT_LE(run.eval.ate.error_m.rmse, 0.01) << "ATE RMSE " << run.eval.ate.error_m.rmse;
}

}  // namespace
}  // namespace detslam
