#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "detslam/core/check.h"
#include "detslam/io/settings.h"
#include "detslam/io/trajectory.h"
#include "detslam/synth/sequence.h"
#include "detslam/synth/synth_test_util.h"
#include "detslam/synth/writer.h"

namespace detslam {
namespace {

namespace fs = std::filesystem;
using synth_test::Slurp;

fs::path TempDir(const std::string& name) { return synth_test::TempDir("detslam_synth_", name); }

TEST(SynthWriterTest, WritesTumLayoutDeterministically) {
  SynthOptions o;
  o.preset = "walking_xyz";
  o.seed = 11;
  o.frames = 4;
  const fs::path a = TempDir("a"), b = TempDir("b");
  const SynthStats stats = WriteSequence(o, a.string());
  WriteSequence(o, b.string());
  EXPECT_EQ(stats.frames, 4);
  EXPECT_GT(stats.render_fps, 0.0);
  EXPECT_GT(stats.mean_fast_corners, 1000.0);

  // Ground truth: one TUM line per frame, equal to the sequence's poses at the colour stamps.
  const Trajectory gt = ReadTumTrajectory((a / "groundtruth.txt").string());
  ASSERT_EQ(gt.size(), 4u);
  SyntheticSequence seq(o);
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(gt[k].stamp, seq.StampOf(k));
    EXPECT_TRUE(gt[k].world_from_cam.Matrix().isApprox(seq.WorldFromCam(k).Matrix(), 1e-8));
    const std::string stamp = seq.StampOf(k).ToString();
    const cv::Mat rgb = cv::imread((a / "rgb" / (stamp + ".png")).string(), cv::IMREAD_UNCHANGED);
    const cv::Mat depth = cv::imread(
        (a / "depth" / (seq.DepthStampOf(k).ToString() + ".png")).string(), cv::IMREAD_UNCHANGED);
    const cv::Mat mask =
        cv::imread((a / "masks" / (stamp + ".png")).string(), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(rgb.empty());
    ASSERT_FALSE(depth.empty());
    ASSERT_FALSE(mask.empty());
    EXPECT_EQ(rgb.type(), CV_8UC3);
    EXPECT_EQ(depth.type(), CV_16U);
    EXPECT_EQ(mask.type(), CV_16U);
    EXPECT_EQ(cv::norm(depth, seq.Render(k).depth16, cv::NORM_INF), 0.0);
  }
  // rgb.txt / depth.txt: TUM header comments then `timestamp path`.
  std::istringstream rgb_txt(Slurp(a / "rgb.txt"));
  std::string line;
  int entries = 0;
  while (std::getline(rgb_txt, line)) {
    if (line.empty() || line[0] == '#') continue;
    EXPECT_EQ(line,
              seq.StampOf(entries).ToString() + " rgb/" + seq.StampOf(entries).ToString() + ".png");
    ++entries;
  }
  EXPECT_EQ(entries, 4);
  EXPECT_NE(Slurp(a / "masks" / "instances.txt").find("# timestamp id class score x y w h"),
            std::string::npos);
  // settings.yaml reads back as the fr3 camera with ORB-SLAM3 v1.0 keys.
  const std::string yaml = Slurp(a / "settings.yaml");
  EXPECT_EQ(yaml.rfind("%YAML:1.0", 0), 0u);
  const Settings s = ReadSettings((a / "settings.yaml").string());
  EXPECT_DOUBLE_EQ(s.camera.fx, 535.4);
  EXPECT_DOUBLE_EQ(s.camera.cy, 247.6);
  EXPECT_DOUBLE_EQ(s.camera.depth_map_factor, 5000.0);
  EXPECT_NEAR(s.camera.Baseline(), 0.0747, 1e-9);
  EXPECT_EQ(s.orb.n_features, 1000);

  // Byte-identical second run.
  int compared = 0;
  for (const auto& entry : fs::recursive_directory_iterator(a)) {
    if (!entry.is_regular_file()) continue;
    const fs::path rel = fs::relative(entry.path(), a);
    EXPECT_EQ(Slurp(entry.path()), Slurp(b / rel)) << rel;
    ++compared;
  }
  EXPECT_EQ(compared, 4 * 3 + 5);  // 12 PNGs, rgb/depth.txt, groundtruth, instances, settings
  fs::remove_all(a);
  fs::remove_all(b);
}

TEST(SynthWriterTest, MissingPeopleFolderNamesIt) {
  SynthOptions o;
  o.people_dir = "/nonexistent/people_dir";
  try {
    SyntheticSequence seq(o);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/people_dir"), std::string::npos);
  }
}

TEST(SynthWriterTest, CutOutWithoutAlphaNamesTheFile) {
  const fs::path dir = TempDir("noalpha");
  fs::create_directories(dir);
  const std::string file = (dir / "person_x.png").string();
  ASSERT_TRUE(cv::imwrite(file, cv::Mat(40, 20, CV_8UC3, cv::Scalar(1, 2, 3))));
  SynthOptions o;
  o.people_dir = dir.string();
  try {
    SyntheticSequence seq(o);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("alpha"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace detslam
