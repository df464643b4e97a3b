#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "detslam/core/check.h"
#include "detslam/io/settings.h"

namespace detslam {
namespace {
namespace fs = std::filesystem;
using ::testing::HasSubstr;

TEST(Presets, TumAndBonnValues) {
  for (const std::string name : {"fr1", "fr2", "fr3", "bonn", "FR2", "freiburg3"}) {
    const Settings s = PresetByName(name);
    std::string error;
    EXPECT_TRUE(s.camera.Check(&error)) << name << ": " << error;
    EXPECT_EQ(s.camera.width, 640) << name;
    EXPECT_EQ(s.camera.height, 480) << name;
    EXPECT_DOUBLE_EQ(s.camera.fps, 30.0) << name;
    EXPECT_DOUBLE_EQ(s.camera.bf, 40.0) << name;
    EXPECT_DOUBLE_EQ(s.camera.th_depth, 40.0) << name;
    EXPECT_THAT(s.source, HasSubstr("preset")) << name;
  }
  const Settings fr1 = PresetByName("fr1");
  EXPECT_DOUBLE_EQ(fr1.camera.fx, 517.306408);
  EXPECT_DOUBLE_EQ(fr1.camera.k3, 1.163314);
  EXPECT_DOUBLE_EQ(fr1.camera.depth_map_factor, 5000.0);
  const Settings fr2 = PresetByName("fr2");
  EXPECT_DOUBLE_EQ(fr2.camera.cx, 325.141442);
  EXPECT_DOUBLE_EQ(fr2.camera.k2, -0.784899);
  EXPECT_DOUBLE_EQ(fr2.camera.depth_map_factor, 5208.0);
  const Settings fr3 = PresetByName("fr3");
  EXPECT_DOUBLE_EQ(fr3.camera.fy, 539.2);
  EXPECT_FALSE(fr3.camera.HasDistortion());
  EXPECT_DOUBLE_EQ(fr3.camera.depth_map_factor, 5000.0);
  const Settings bonn = PresetByName("bonn");
  EXPECT_DOUBLE_EQ(bonn.camera.fx, 542.822841);
  EXPECT_DOUBLE_EQ(bonn.camera.cy, 237.756098);
  EXPECT_DOUBLE_EQ(bonn.camera.p1, -0.000730);
  EXPECT_DOUBLE_EQ(bonn.camera.k3, 0.000920);
  EXPECT_DOUBLE_EQ(bonn.camera.depth_map_factor, 5000.0);
  try {
    PresetByName("fr4");
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("'fr4'"));
    EXPECT_THAT(e.what(), HasSubstr("fr1, fr2, fr3, bonn"));
  }
}

TEST(Presets, ChosenFromFolderName) {
  const fs::path root =
      fs::temp_directory_path() / ("detslam_io_presets_" + std::to_string(::getpid()));
  EXPECT_DOUBLE_EQ(
      PresetForDataset((root / "rgbd_dataset_freiburg3_walking_xyz").string()).camera.fx, 535.4);
  EXPECT_DOUBLE_EQ(PresetForDataset((root / "rgbd_dataset_freiburg2_desk/").string()).camera.fx,
                   520.908620);
  EXPECT_DOUBLE_EQ(PresetForDataset((root / "my_fr1_room").string()).camera.fx, 517.306408);
  EXPECT_DOUBLE_EQ(PresetForDataset((root / "rgbd_bonn_balloon").string()).camera.fx, 542.822841);
  try {
    PresetForDataset((root / "mystery_sequence").string());
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("mystery_sequence"));
    EXPECT_THAT(e.what(), HasSubstr("no camera preset matches"));
    EXPECT_THAT(e.what(), HasSubstr("--config FILE"));
  }
  EXPECT_THROW(PresetForDataset((root / "fr1_vs_fr3").string()), InputError);
}

TEST(Presets, SettingsYamlInTheFolderWins) {
  const fs::path dir = fs::temp_directory_path() /
                       ("detslam_io_presets_" + std::to_string(::getpid())) /
                       "rgbd_dataset_freiburg1_synthetic";
  fs::create_directories(dir);
  Settings own = PresetByName("fr3");
  own.camera.fx = 400.0;
  own.camera.width = 320;
  WriteSettings((dir / "settings.yaml").string(), own);
  const Settings chosen = PresetForDataset(dir.string());
  EXPECT_DOUBLE_EQ(chosen.camera.fx, 400.0);
  EXPECT_EQ(chosen.camera.width, 320);
  EXPECT_EQ(chosen.source, (dir / "settings.yaml").string());
  fs::remove_all(dir.parent_path());
}

}  // namespace
}  // namespace detslam
