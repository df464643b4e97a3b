#include "detslam/io/dataset.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "detslam/core/check.h"

namespace detslam {
namespace {
namespace fs = std::filesystem;
using ::testing::HasSubstr;

constexpr int kWidth = 8;
constexpr int kHeight = 6;

// A fresh folder per test, removed afterwards.
class RgbdDatasetTest : public ::testing::Test {
 protected:
  void SetUp() override {
    static int counter = 0;
    dir_ = fs::temp_directory_path() /
           ("detslam_io_dataset_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "rgb");
    fs::create_directories(dir_ / "depth");
    camera_.width = kWidth;
    camera_.height = kHeight;
    camera_.depth_map_factor = 5000.0;
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Path(const std::string& rel) const { return (dir_ / rel).string(); }
  void WriteText(const std::string& rel, const std::string& text) const {
    std::ofstream(Path(rel)) << text;
  }
  // Colour image whose blue channel encodes `seed`, and a depth image of constant `depth_value`.
  void WriteColour(const std::string& rel, int seed, int width = kWidth) const {
    cv::Mat bgr(kHeight, width, CV_8UC3, cv::Scalar(seed, 100, 200));
    ASSERT_TRUE(cv::imwrite(Path(rel), bgr));
  }
  void WriteDepth(const std::string& rel, uint16_t depth_value, int width = kWidth) const {
    cv::Mat depth(kHeight, width, CV_16UC1, cv::Scalar(depth_value));
    ASSERT_TRUE(cv::imwrite(Path(rel), depth));
  }
  // rgb.txt / depth.txt with one image per stamp (the images are created too).
  void WriteSequence(const std::vector<std::string>& rgb_stamps,
                     const std::vector<std::string>& depth_stamps) const {
    std::string rgb = "# color images\n# timestamp filename\n";
    for (size_t i = 0; i < rgb_stamps.size(); ++i) {
      rgb += rgb_stamps[i] + " rgb/" + rgb_stamps[i] + ".png\n";
      WriteColour("rgb/" + rgb_stamps[i] + ".png", static_cast<int>(10 * i));
    }
    std::string depth = "# depth maps\n";
    for (const std::string& s : depth_stamps) {
      depth += s + " depth/" + s + ".png\n";
      WriteDepth("depth/" + s + ".png", 5000);
    }
    WriteText("rgb.txt", rgb);
    WriteText("depth.txt", depth);
  }
  std::string OpenError(const DatasetOptions& options = {}) const {
    try {
      RgbdDataset::Open(dir_.string(), options);
    } catch (const InputError& e) {
      return e.what();
    }
    ADD_FAILURE() << "no InputError";
    return "";
  }

  fs::path dir_;
  PinholeCamera camera_;
};

TEST_F(RgbdDatasetTest, AssociatesGreedilyWithinWindow) {
  WriteSequence({"1.000000", "1.033000", "1.066000"}, {"1.005000", "1.040000", "1.100000"});
  const RgbdDataset d = RgbdDataset::Open(dir_.string(), {});
  // 1.066 has no depth within 0.02 s (closest 1.100 is 0.034 away).
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(d.frame(0).rgb_stamp, Timestamp::FromSeconds(1.0));
  EXPECT_EQ(d.frame(0).depth_stamp, Timestamp::FromSeconds(1.005));
  EXPECT_EQ(d.frame(1).rgb_stamp, Timestamp::FromSeconds(1.033));
  EXPECT_EQ(d.frame(1).depth_stamp, Timestamp::FromSeconds(1.04));
  EXPECT_TRUE(fs::path(d.frame(1).rgb_path).is_absolute());
  EXPECT_TRUE(fs::equivalent(d.frame(1).rgb_path, Path("rgb/1.033000.png")));
  EXPECT_TRUE(fs::equivalent(d.frame(1).depth_path, Path("depth/1.040000.png")));
  EXPECT_TRUE(fs::equivalent(d.dir(), dir_));
  EXPECT_EQ(d.groundtruth_path(), "");
  WriteText("groundtruth.txt", "1.0 0 0 0 0 0 0 1\n");
  EXPECT_TRUE(fs::equivalent(d.groundtruth_path(), Path("groundtruth.txt")));
}

TEST_F(RgbdDatasetTest, OffsetShiftsDepthStamps) {
  WriteSequence({"1.000000", "1.100000"}, {"1.050000", "1.150000"});
  const std::string error = OpenError();
  EXPECT_THAT(error, HasSubstr("nothing associated"));
  EXPECT_THAT(error, HasSubstr("0.02"));
  DatasetOptions options;
  options.offset_s = -0.05;
  const RgbdDataset d = RgbdDataset::Open(dir_.string(), options);
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(d.frame(1).depth_stamp, Timestamp::FromSeconds(1.15));
  options.max_difference_s = 0.0;
  EXPECT_THAT(OpenError(options), HasSubstr("max_difference_s"));
}

TEST_F(RgbdDatasetTest, LoadConvertsDepthToMetres) {
  WriteText("rgb.txt", "1.0 rgb/a.png\n");
  WriteText("depth.txt", "1.0 depth/a.png\n");
  WriteColour("rgb/a.png", 50);
  cv::Mat depth(kHeight, kWidth, CV_16UC1, cv::Scalar(0));
  depth.at<uint16_t>(2, 3) = 7500;
  depth.at<uint16_t>(4, 5) = 65535;
  ASSERT_TRUE(cv::imwrite(Path("depth/a.png"), depth));
  const RgbdImages images = RgbdDataset::Open(dir_.string(), {}).Load(0, camera_);
  ASSERT_EQ(images.bgr.type(), CV_8UC3);
  ASSERT_EQ(images.gray.type(), CV_8UC1);
  ASSERT_EQ(images.depth_m.type(), CV_32FC1);
  EXPECT_EQ(images.bgr.at<cv::Vec3b>(1, 1), cv::Vec3b(50, 100, 200));
  // OpenCV's BGR->gray weights: 0.114 B + 0.587 G + 0.299 R.
  EXPECT_NEAR(images.gray.at<uint8_t>(1, 1), 0.114 * 50 + 0.587 * 100 + 0.299 * 200, 1.0);
  EXPECT_FLOAT_EQ(images.depth_m.at<float>(2, 3), 1.5f);
  EXPECT_FLOAT_EQ(images.depth_m.at<float>(4, 5), 65535.0f / 5000.0f);
  EXPECT_EQ(images.depth_m.at<float>(0, 0), 0.0f);
  camera_.depth_map_factor = 5208.0;
  EXPECT_FLOAT_EQ(RgbdDataset::Open(dir_.string(), {}).Load(0, camera_).depth_m.at<float>(2, 3),
                  static_cast<float>(7500.0 / 5208.0));
}

TEST_F(RgbdDatasetTest, LoadConvertsGrayAndFourChannelColour) {
  WriteText("rgb.txt", "1.0 rgb/g.png\n2.0 rgb/c.png\n");
  WriteText("depth.txt", "1.0 depth/a.png\n2.0 depth/b.png\n");
  ASSERT_TRUE(cv::imwrite(Path("rgb/g.png"), cv::Mat(kHeight, kWidth, CV_8UC1, cv::Scalar(77))));
  ASSERT_TRUE(
      cv::imwrite(Path("rgb/c.png"), cv::Mat(kHeight, kWidth, CV_8UC4, cv::Scalar(1, 2, 3, 128))));
  WriteDepth("depth/a.png", 1000);
  WriteDepth("depth/b.png", 1000);
  const RgbdDataset d = RgbdDataset::Open(dir_.string(), {});
  const RgbdImages gray = d.Load(0, camera_);
  ASSERT_EQ(gray.bgr.type(), CV_8UC3);
  EXPECT_EQ(gray.bgr.at<cv::Vec3b>(0, 0), cv::Vec3b(77, 77, 77));
  EXPECT_EQ(gray.gray.at<uint8_t>(0, 0), 77);
  const RgbdImages four = d.Load(1, camera_);
  ASSERT_EQ(four.bgr.type(), CV_8UC3);
  EXPECT_EQ(four.bgr.at<cv::Vec3b>(5, 7), cv::Vec3b(1, 2, 3));
}

TEST_F(RgbdDatasetTest, LoadRejectsBadImagesNamingTheFile) {
  WriteText("rgb.txt", "1.0 rgb/a.png\n2.0 rgb/b.png\n3.0 rgb/c.png\n4.0 rgb/d.png\n");
  WriteText("depth.txt", "1.0 depth/a.png\n2.0 depth/b.png\n3.0 depth/c.png\n4.0 depth/d.png\n");
  for (const char* name : {"a", "b", "c"}) WriteColour(std::string("rgb/") + name + ".png", 0);
  WriteText("rgb/d.png", "not a png");
  ASSERT_TRUE(cv::imwrite(Path("depth/a.png"), cv::Mat(kHeight, kWidth, CV_8UC1)));  // 8-bit
  WriteDepth("depth/b.png", 1, kWidth + 2);                                          // size
  WriteDepth("depth/c.png", 1);
  WriteDepth("depth/d.png", 1);
  const RgbdDataset d = RgbdDataset::Open(dir_.string(), {});
  auto load_error = [&](size_t i, const PinholeCamera& camera) -> std::string {
    try {
      d.Load(i, camera);
    } catch (const InputError& e) {
      return e.what();
    }
    return "no InputError";
  };
  EXPECT_THAT(load_error(0, camera_), HasSubstr("depth/a.png"));
  EXPECT_THAT(load_error(0, camera_), HasSubstr("16-bit"));
  EXPECT_THAT(load_error(1, camera_), HasSubstr("depth/b.png"));
  EXPECT_THAT(load_error(1, camera_), HasSubstr("10x6"));
  EXPECT_THAT(load_error(3, camera_), HasSubstr("rgb/d.png"));
  EXPECT_THAT(load_error(3, camera_), HasSubstr("cannot decode"));
  PinholeCamera wrong = camera_;
  wrong.width = 640;
  EXPECT_THAT(load_error(2, wrong), HasSubstr("rgb/c.png"));
  EXPECT_THAT(load_error(2, wrong), HasSubstr("640x6"));
  EXPECT_NO_THROW(d.Load(2, camera_));
}

TEST_F(RgbdDatasetTest, MissingFolderAndListsAreErrors) {
  EXPECT_THAT(OpenError(), HasSubstr("rgb.txt"));
  WriteText("rgb.txt", "");
  EXPECT_THAT(OpenError(), HasSubstr("depth.txt"));
  WriteText("depth.txt", "# only a comment\n");
  EXPECT_THAT(OpenError(), HasSubstr("no images"));
  try {
    RgbdDataset::Open(Path("nope"), {});
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("nope"));
    EXPECT_THAT(e.what(), HasSubstr("does not exist"));
  }
}

TEST_F(RgbdDatasetTest, AnImageNameTooLongForTheFileSystemIsAnInputError) {
  // Found by the dataset fuzzer: the throwing std::filesystem call ended the program.
  WriteText("rgb.txt", "0 rgb/" + std::string(300, 's') + ".png\n");
  WriteText("depth.txt", "0 depth/0.png\n");
  EXPECT_THAT(OpenError(), HasSubstr("rgb.txt:1"));
}

TEST_F(RgbdDatasetTest, MalformedLinesNameFileAndLine) {
  WriteSequence({"1.0"}, {"1.0"});
  WriteText("rgb.txt", "# header\n1.0 rgb/1.0.png\n2.0\n");
  EXPECT_THAT(OpenError(), HasSubstr(Path("rgb.txt") + ":3: expected 2 fields"));
  WriteText("rgb.txt", "1.0 rgb/1.0.png\nabc rgb/1.0.png\n");
  EXPECT_THAT(OpenError(), HasSubstr(Path("rgb.txt") + ":2: malformed timestamp 'abc'"));
}

TEST_F(RgbdDatasetTest, OutOfOrderStampsNameTheBreakingLine) {
  WriteSequence({"1.0", "2.0", "3.0"}, {"1.0", "2.0", "3.0"});
  WriteText("depth.txt", "1.0 depth/1.0.png\n# c\n3.0 depth/3.0.png\n2.0 depth/2.0.png\n");
  const std::string error = OpenError();
  EXPECT_THAT(error, HasSubstr(Path("depth.txt") + ":4:"));
  EXPECT_THAT(error, HasSubstr("line 3"));
  WriteText("depth.txt", "1.0 depth/1.0.png\n1.0 depth/1.0.png\n");
  EXPECT_THAT(OpenError(), HasSubstr(Path("depth.txt") + ":2:"));
}

TEST_F(RgbdDatasetTest, MissingImageNamesListLineAndImage) {
  WriteSequence({"1.0", "2.0"}, {"1.0", "2.0"});
  fs::remove(Path("rgb/2.0.png"));
  const std::string error = OpenError();
  // WriteSequence puts two comment lines first, so the second image is on line 4.
  EXPECT_THAT(error, HasSubstr(Path("rgb.txt") + ":4:"));
  EXPECT_THAT(error, HasSubstr("rgb/2.0.png"));
}

TEST_F(RgbdDatasetTest, ExplicitAssociationFile) {
  WriteSequence({"1.0", "2.0", "3.0"}, {"1.01", "2.01", "3.5"});
  WriteText("assoc.txt",
            "# ts rgb ts depth\n1.0 rgb/1.0.png 3.5 depth/3.5.png\n"
            "3.0 rgb/3.0.png 1.01 depth/1.01.png extra columns are ignored\n");
  DatasetOptions options;
  options.association_file = "assoc.txt";  // relative to the dataset folder
  const RgbdDataset d = RgbdDataset::Open(dir_.string(), options);
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(d.frame(0).depth_stamp, Timestamp::FromSeconds(3.5));
  EXPECT_TRUE(fs::equivalent(d.frame(1).rgb_path, Path("rgb/3.0.png")));
  EXPECT_TRUE(fs::equivalent(d.frame(1).depth_path, Path("depth/1.01.png")));

  WriteText("assoc.txt", "1.0 rgb/1.0.png 1.01\n");
  EXPECT_THAT(OpenError(options), HasSubstr(Path("assoc.txt") + ":1: expected at least 4"));
  WriteText("assoc.txt",
            "2.0 rgb/2.0.png 2.01 depth/2.01.png\n1.0 rgb/1.0.png 1.01 depth/1.01.png\n");
  EXPECT_THAT(OpenError(options), HasSubstr(Path("assoc.txt") + ":2:"));
  WriteText("assoc.txt", "1.0 rgb/1.0.png 1.01 depth/missing.png\n");
  EXPECT_THAT(OpenError(options), HasSubstr("depth/missing.png"));
  WriteText("assoc.txt", "");
  EXPECT_THAT(OpenError(options), HasSubstr("no frames"));
  options.association_file = Path("absent.txt");
  EXPECT_THAT(OpenError(options), HasSubstr("absent.txt"));
}

}  // namespace
}  // namespace detslam
