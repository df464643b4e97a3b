// The dense static map end to end: `detslam run --dense-map` on a synthetic walking sequence with
// the generator's masks, scored against the generator's truth, against `detslam densify` of the
// same run with every pixel fused; the threaded runner's keyframe masks give the same map.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "detslam/io/ply.h"
#include "detslam/io/trajectory.h"
#include "detslam/synth/dense_truth.h"
#include "integration_util.h"

namespace detslam {
namespace {
namespace fs = std::filesystem;
using testing::ReadFileBytes;
using testing::RunCli;

std::vector<Eigen::Vector3d> AlignedCloud(const std::string& ply, const Rigid3d& world_from_slam) {
  std::vector<Eigen::Vector3d> points = ReadPointCloudPly(ply).points;
  for (Eigen::Vector3d& p : points) p = world_from_slam * p;
  return points;
}

TEST(IntegrationDenseMap, TheFilteredMapHoldsTheRoomAndNotThePeople) {
  constexpr int kFrames = 100;
  const fs::path dir = testing::TempDir("dense_map");
  const std::string seq = integration::WritePresetSequence("dense_map_seq", "walking_xyz", 2, kFrames);
  const fs::path out = dir / "run", log = dir / "log.txt";
  const std::string dense = (out / "dense_map.ply").string();
  ASSERT_EQ(RunCli("run --dataset '" + seq + "' --segmenter gt --no-progress --out '" + out.string() +
                       "' --dense-map '" + dense + "'",
                   log),
            0)
      << ReadFileBytes(log);
  EXPECT_THAT(ReadFileBytes(log), ::testing::HasSubstr("dense map: " + dense));
  const nlohmann::json run = integration::RunJson(out);
  ASSERT_TRUE(run.contains("dense_map"));
  const size_t keyframes = run["keyframes"];
  EXPECT_EQ(run["dense_map"]["keyframes_fused"], keyframes);
  EXPECT_GT(run["keyframe_masks"].get<size_t>(), 0u);  // people were in view of some keyframes
  EXPECT_EQ(run["dense_map"]["keyframes_masked"], run["keyframe_masks"]);
  size_t mask_files = 0;
  for (const auto& e : fs::directory_iterator(out / "keyframe_masks")) mask_files += e.path().extension() == ".png";
  EXPECT_EQ(mask_files, run["keyframe_masks"].get<size_t>());

  // Every pixel fused, no carving: the people smear into the map.
  const std::string smeared = (dir / "smeared.ply").string();
  ASSERT_EQ(RunCli("densify '" + out.string() + "' --keep-dynamic --no-carve --no-progress --out '" +
                       smeared + "'",
                   log),
            0)
      << ReadFileBytes(log);

  SynthOptions so;
  so.preset = "walking_xyz";
  so.seed = 2;
  so.frames = kFrames;
  const SyntheticSequence sequence(so);
  const Rigid3d world_from_slam =
      AlignRunToSequence(sequence, ReadTumTrajectory((out / "trajectory.txt").string()));
  const std::vector<int> kf_frames =
      SequenceFramesOf(sequence, ReadTumTrajectory((out / "keyframes.txt").string()));
  ASSERT_EQ(kf_frames.size(), keyframes);
  const DenseTruth truth(sequence, kf_frames, DenseTruthOptions());
  const DenseMapScore filtered = truth.Score(AlignedCloud(dense, world_from_slam));
  const DenseMapScore all = truth.Score(AlignedCloud(smeared, world_from_slam));
  EXPECT_GT(filtered.points, 100000u);
  EXPECT_LT(filtered.SmearFraction(), 0.01) << filtered.near_person_off_scene << " of " << filtered.points;
  EXPECT_LE(filtered.static_median_m, 0.01);
  EXPECT_GT(filtered.completeness, 0.8);
  EXPECT_GT(all.SmearFraction(), 0.02) << "the comparison must show people without the filter";
  EXPECT_GT(all.SmearFraction(), 5 * filtered.SmearFraction());

  // The threaded runner (mapping in the tracking thread: the sequential trajectory) records the
  // same keyframe masks and so writes the same dense map.
  const fs::path threaded = dir / "threaded";
  ASSERT_EQ(RunCli("run --dataset '" + seq + "' --segmenter gt --no-progress --threaded --inline-mapping --out '" +
                       threaded.string() + "' --dense-map '" + (threaded / "dense_map.ply").string() + "'",
                   log),
            0)
      << ReadFileBytes(log);
  EXPECT_EQ(ReadFileBytes(threaded / "dense_map.ply"), ReadFileBytes(dense));
  fs::remove_all(dir);
  fs::remove_all(seq);
}

TEST(IntegrationDenseMap, DensifyNamesWhatIsMissing) {
  const fs::path dir = testing::TempDir("densify_errors");
  const fs::path log = dir / "log.txt";
  EXPECT_EQ(RunCli("densify '" + (dir / "nothing").string() + "'", log), 1);
  EXPECT_THAT(ReadFileBytes(log), ::testing::HasSubstr("run.json"));
  fs::create_directories(dir / "run");
  { std::ofstream(dir / "run" / "run.json") << "{\"dataset\": \"" << (dir / "gone").string() << "\"}\n"; }
  EXPECT_EQ(RunCli("densify '" + (dir / "run").string() + "'", log), 1);
  EXPECT_THAT(ReadFileBytes(log), ::testing::HasSubstr((dir / "gone").string()));
  EXPECT_EQ(RunCli("densify '" + (dir / "run").string() + "' --voxel-size 0", log), 1);
  EXPECT_THAT(ReadFileBytes(log), ::testing::HasSubstr("voxel size must lie in"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace detslam
