// `detslam vocab train|info` end to end on a few generated images, and its errors on bad input.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

namespace detslam {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

int Cli(const std::string& args, const fs::path& log) {
  const std::string cmd =
      std::string(DETSLAM_CLI_PATH) + " " + args + " > '" + log.string() + "' 2>&1";
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string Read(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

TEST(IntegrationVocabCli, TrainThenInfoDeterministic) {
  const fs::path dir = fs::temp_directory_path() / "detslam_it_vocab";
  fs::remove_all(dir);
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
  ASSERT_EQ(Cli(train + "'" + a.string() + "'", log), 0) << Read(log);
  EXPECT_THAT(Read(log), HasSubstr("images read 5 / 5"));
  EXPECT_THAT(Read(log), HasSubstr("level 2 / 2"));
  ASSERT_EQ(Cli(train + "'" + b.string() + "'", log), 0) << Read(log);
  EXPECT_EQ(Read(a), Read(b));  // same seed, same bytes

  ASSERT_EQ(Cli("vocab info '" + a.string() + "'", log), 0) << Read(log);
  EXPECT_THAT(Read(log), HasSubstr("words: 16"));
  EXPECT_THAT(Read(log), HasSubstr("k: 4"));
  EXPECT_THAT(Read(log), HasSubstr("training images: 5"));

  ASSERT_EQ(Cli("vocab train --k 4 --levels 2 --images '" + (dir / "list.txt").string() +
                    "' --out '" + c.string() + "'",
                log),
            0)
      << Read(log);
  ASSERT_EQ(Cli("vocab info '" + c.string() + "'", log), 0) << Read(log);
  EXPECT_THAT(Read(log), HasSubstr("training images: 2"));

  // Bad input: exit 1 with the file named.
  EXPECT_EQ(Cli("vocab train --images '" + (dir / "nope").string() + "' --out x.voc", log), 1);
  EXPECT_THAT(Read(log), HasSubstr("error: " + (dir / "nope").string()));
  std::ofstream(dir / "empty.txt") << "\n";
  EXPECT_EQ(Cli("vocab train --images '" + (dir / "empty.txt").string() + "' --out x.voc", log), 1);
  EXPECT_THAT(Read(log), HasSubstr("no images found"));
  std::ofstream(dir / "broken.voc") << "DSLMVOC";
  EXPECT_EQ(Cli("vocab info '" + (dir / "broken.voc").string() + "'", log), 1);
  EXPECT_THAT(Read(log), HasSubstr("truncated"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace detslam
