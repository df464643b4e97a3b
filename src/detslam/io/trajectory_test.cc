#include "detslam/io/trajectory.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "detslam/core/check.h"
#include "support/cli_runner.h"

namespace detslam {
namespace {

using testing::TempPath;

void WriteText(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

TEST(Trajectory, WriteReadRoundTrip) {
  Trajectory t;
  Timestamp stamp;
  ASSERT_TRUE(ParseTimestamp("1311868164.363181", &stamp));
  t.push_back({stamp,
               Rigid3d(Eigen::Quaterniond(0.5, 0.5, -0.5, 0.5), Eigen::Vector3d(1.5, -2, 0.25))});
  const std::string path = TempPath("roundtrip.txt");
  WriteTumTrajectory(path, t, "test header");
  const Trajectory back = ReadTumTrajectory(path);
  ASSERT_EQ(back.size(), 1u);
  EXPECT_EQ(back[0].stamp, t[0].stamp);
  EXPECT_LT((back[0].world_from_cam.translation() - t[0].world_from_cam.translation()).norm(), 1e-9);
  EXPECT_LT(back[0].world_from_cam.rotation().angularDistance(t[0].world_from_cam.rotation()), 1e-8);
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
}

TEST(Trajectory, MalformedLineNamesFileAndLine) {
  const std::string path = TempPath("bad.txt");
  WriteText(path, "# comment\n1.0 0 0 0 0 0 0 1\n2.0 0 0 zero 0 0 0 1\n");
  try {
    ReadTumTrajectory(path);
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path + ":3"), std::string::npos) << e.what();
  }
}

TEST(Trajectory, ShortLineAndMissingFileAreErrors) {
  const std::string path = TempPath("short.txt");
  WriteText(path, "1.0 0 0 0\n");
  EXPECT_THROW(ReadTumTrajectory(path), InputError);
  EXPECT_THROW(ReadTumTrajectory(TempPath("does_not_exist.txt")), InputError);
}

TEST(Trajectory, NonFiniteAndHugeValuesNameFileAndLine) {
  const std::string path = TempPath("huge.txt");
  for (const std::string bad : {"2.0 nan 0 0 0 0 0 1", "2.0 0 inf 0 0 0 0 1", "2.0 0 0 2e6 0 0 0 1",
                                "2.0 0 0 0 1e300 1e300 0 1", "2.0 0 0 0 0 0 0 0"}) {
    WriteText(path, "1.0 0 0 0 0 0 0 1\n" + bad + "\n");
    try {
      ReadTumTrajectory(path);
      ADD_FAILURE() << "no error for " << bad;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path + ":2"), std::string::npos) << e.what();
    }
  }
  WriteText(path, "1.0 0 0 0 0 0 0 1\n2.0 0 0 9e5 0 0 0 1\n");  // large but possible
  EXPECT_EQ(ReadTumTrajectory(path).size(), 2u);
}

TEST(Trajectory, AcceptsCommasAndTabs) {
  const std::string path = TempPath("commas.txt");
  WriteText(path, "1.0,1,2,3,0,0,0,1\n2.0\t1\t2\t3\t0\t0\t0\t2\n");
  const Trajectory t = ReadTumTrajectory(path);
  ASSERT_EQ(t.size(), 2u);
  EXPECT_NEAR(t[1].world_from_cam.rotation().w(), 1.0, 1e-12);  // normalised
}

TEST(Trajectory, FailedWriteLeavesOldFileIntact) {
  const std::string path = TempPath("atomic.txt");
  WriteText(path, "1.0 0 0 0 0 0 0 1\n");
  EXPECT_THROW(WriteTumTrajectory(path + "/sub/impossible", {}, ""), InputError);
  EXPECT_EQ(ReadTumTrajectory(path).size(), 1u);
}

}  // namespace
}  // namespace detslam
