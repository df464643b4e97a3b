// `detslam vocab train|info` end to end on a few generated images, and its errors on bad input.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "support/cli_runner.h"
#include "support/shared_data.h"

namespace detslam {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using testing::ReadFileBytes;
using testing::RunCli;

TEST(IntegrationVocabCli, TrainThenInfoDeterministic) {
  const fs::path dir = testing::TempDir("vocab");
  fs::create_directories(dir / "images");
  cv::RNG rng(3);
  for (int i = 0; i < 5; ++i) {  // blocky random texture: plenty of FAST corners
    cv::Mat small(30, 40, CV_8UC1), image;
    rng.fill(small, cv::RNG::UNIFORM, 0, 256);
    cv::resize(small, image, cv::Size(320, 240), 0, 0, cv::INTER_NEAREST);
    cv::imwrite((dir / "images" / (std::to_string(i) + ".png")).string(), image);
  }
  std::ofstream(dir / "list.txt") << "# two of them\nimages/0.png\n1.0 images/3.png\n";
  const fs::path log = dir / "log.txt", a = dir / "a.voc", b = dir / "b.voc", c = dir / "c.voc";
  const std::string train = "vocab train --k 4 --levels 2 --features 200 --seed 3 --images '" +
                            (dir / "images").string() + "' --out ";
  ASSERT_EQ(RunCli(train + "'" + a.string() + "'", log), 0) << ReadFileBytes(log);
  EXPECT_THAT(ReadFileBytes(log), HasSubstr("images read 5 / 5"));
  EXPECT_THAT(ReadFileBytes(log), HasSubstr("level 2 / 2"));
  ASSERT_EQ(RunCli(train + "'" + b.string() + "'", log), 0) << ReadFileBytes(log);
  EXPECT_EQ(ReadFileBytes(a), ReadFileBytes(b));  // same seed, same bytes

  ASSERT_EQ(RunCli("vocab info '" + a.string() + "'", log), 0) << ReadFileBytes(log);
  EXPECT_THAT(ReadFileBytes(log), HasSubstr("words: 16"));
  EXPECT_THAT(ReadFileBytes(log), HasSubstr("k: 4"));
  EXPECT_THAT(ReadFileBytes(log), HasSubstr("training images: 5"));

  ASSERT_EQ(RunCli("vocab train --k 4 --levels 2 --images '" + (dir / "list.txt").string() +
                       "' --out '" + c.string() + "'",
                   log),
            0)
      << ReadFileBytes(log);
  ASSERT_EQ(RunCli("vocab info '" + c.string() + "'", log), 0) << ReadFileBytes(log);
  EXPECT_THAT(ReadFileBytes(log), HasSubstr("training images: 2"));

  // Bad input: exit 1 with the file named.
  EXPECT_EQ(RunCli("vocab train --images '" + (dir / "nope").string() + "' --out x.voc", log), 1);
  EXPECT_THAT(ReadFileBytes(log), HasSubstr("error: " + (dir / "nope").string()));
  std::ofstream(dir / "empty.txt") << "\n";
  EXPECT_EQ(RunCli("vocab train --images '" + (dir / "empty.txt").string() + "' --out x.voc", log),
            1);
  EXPECT_THAT(ReadFileBytes(log), HasSubstr("no images found"));
  std::ofstream(dir / "broken.voc") << "DSLMVOC";
  EXPECT_EQ(RunCli("vocab info '" + (dir / "broken.voc").string() + "'", log), 1);
  EXPECT_THAT(ReadFileBytes(log), HasSubstr("truncated"));
  fs::remove_all(dir);
}

// `detslam run` with a vocabulary it cannot use stops with the file named, before writing outputs;
// with none it runs without place recognition and says so in run.json.
TEST(IntegrationVocabCli, RunNamesABadVocabularyAndRunsWithNone) {
  const fs::path dir = testing::TempDir("vocab_run");
  const fs::path log = dir / "log.txt";
  ASSERT_EQ(RunCli("synth --preset static --frames 3 --out '" + (dir / "seq").string() + "'", log),
            0)
      << ReadFileBytes(log);
  const std::string run =
      "run --no-progress --segmenter none --dataset '" + (dir / "seq").string() + "' --out '";
  std::ofstream(dir / "bad.dslvoc") << "DSLMVOC\0garbage";
  EXPECT_EQ(RunCli(run + (dir / "out1").string() + "' --vocabulary '" +
                       (dir / "bad.dslvoc").string() + "'",
                   log),
            1);
  EXPECT_THAT(ReadFileBytes(log), HasSubstr("error: " + (dir / "bad.dslvoc").string()));
  EXPECT_FALSE(fs::exists(dir / "out1" / "trajectory.txt"));
  ASSERT_EQ(RunCli(run + (dir / "out2").string() + "' --vocabulary none", log), 0)
      << ReadFileBytes(log);
  EXPECT_THAT(ReadFileBytes(dir / "out2" / "run.json"), HasSubstr("\"vocabulary\": \"none\""));
  fs::remove_all(dir);
}

// The shipped vocabulary is what its recipe (data/vocabulary/README.md) builds, byte for byte: its
// training images are the Debian packages' photographs and ../shared's TUM frames.
TEST(DataVocabulary, ShippedFileIsReproducible) {
  const fs::path folder = fs::path(DETSLAM_SOURCE_DIR) / "data" / "vocabulary";
  const fs::path sources = folder / "sources.txt";
  std::ifstream in(sources);
  ASSERT_TRUE(in) << sources;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    const fs::path image = fs::path(line).is_absolute() ? fs::path(line) : folder / line;
    if (fs::exists(image)) continue;
    const std::string why = "training image missing: " + image.string() +
                            " (apt-get install opencv-doc mate-backgrounds; ../shared)";
    if (testing::InCi()) FAIL() << why;
    GTEST_SKIP() << why;
  }
  const fs::path dir = testing::TempDir("data_vocab");
  const fs::path log = dir / "log.txt", out = dir / "rebuilt.dslvoc";
  ASSERT_EQ(RunCli("vocab train --images '" + sources.string() +
                       "' --k 10 --levels 5 --features 8000 --seed 1 --out '" + out.string() + "'",
                   log),
            0)
      << ReadFileBytes(log);
  const std::string rebuilt = ReadFileBytes(out);
  ASSERT_FALSE(rebuilt.empty());
  EXPECT_TRUE(rebuilt == ReadFileBytes(folder / "orb_k10_l5.dslvoc"))
      << "the rebuilt vocabulary differs from data/vocabulary/orb_k10_l5.dslvoc";
  fs::remove_all(dir);
}

}  // namespace
}  // namespace detslam
