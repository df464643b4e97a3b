#include "detslam/segmentation/mask_dir.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "detslam/core/check.h"

namespace detslam {
namespace {
namespace fs = std::filesystem;

class MaskDirTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("detslam_maskdir_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  void WriteList(const std::string& text) { std::ofstream(dir_ / "instances.txt") << text; }
  SegmenterInput Frame(const std::string& stamp, cv::Size size = cv::Size(64, 48)) {
    SegmenterInput in;
    EXPECT_TRUE(ParseTimestamp(stamp, &in.stamp));
    in.bgr = cv::Mat(size, CV_8UC3, cv::Scalar(0, 0, 0));
    return in;
  }
  std::string ErrorOf(const std::function<void()>& fn) {
    try {
      fn();
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  }
  fs::path dir_;
};

Instance MakeInstance(int class_id, const std::string& name, float score, cv::Rect box,
                      cv::Size size, bool with_mask) {
  Instance in;
  in.class_id = class_id;
  in.class_name = name;
  in.score = score;
  in.box = box;
  if (with_mask) {
    in.mask = cv::Mat(size, CV_8UC1, cv::Scalar(0));
    cv::ellipse(in.mask, (box.tl() + box.br()) / 2, box.size() / 2, 0, 0, 360, 255, cv::FILLED);
  }
  return in;
}

TEST_F(MaskDirTest, WriteThenReadRoundTrip) {
  const cv::Size size(64, 48);
  Timestamp t0, t1, t2;
  ASSERT_TRUE(ParseTimestamp("1341846313.592026", &t0));
  ASSERT_TRUE(ParseTimestamp("1341846313.625000", &t1));
  ASSERT_TRUE(ParseTimestamp("1341846313.660000", &t2));
  std::vector<std::vector<Instance>> frames(3);
  frames[0].push_back(MakeInstance(0, "person", 0.9f, cv::Rect(4, 4, 20, 30), size, true));
  frames[0].push_back(MakeInstance(9, "traffic light", 0.5f, cv::Rect(40, 10, 10, 8), size, false));
  frames[2].push_back(MakeInstance(0, "person", 0.75f, cv::Rect(30, 5, 25, 40), size, true));
  WriteMasks(dir_.string(), {t0, t1, t2}, frames, size);
  EXPECT_TRUE(fs::exists(MaskPngPath(dir_.string(), t0)));
  EXPECT_FALSE(fs::exists(MaskPngPath(dir_.string(), t1))) << "no PNG for a frame without objects";
  const cv::Mat png = cv::imread(MaskPngPath(dir_.string(), t0), cv::IMREAD_UNCHANGED);
  EXPECT_EQ(png.type(), CV_16UC1);

  MaskDirSegmenter seg(dir_.string());
  EXPECT_EQ(seg.listed_frames(), 2u);
  const std::vector<Timestamp> stamps = {t0, t1, t2};
  for (size_t f = 0; f < 3; ++f) {
    SegmenterInput in;
    in.stamp = stamps[f];
    in.bgr = cv::Mat(size, CV_8UC3);
    const auto got = seg.Segment(in);
    ASSERT_EQ(got.size(), frames[f].size()) << "frame " << f;
    for (size_t k = 0; k < got.size(); ++k) {
      const Instance& want = frames[f][k];
      EXPECT_EQ(got[k].class_id, want.class_id);
      EXPECT_EQ(got[k].class_name, want.class_name);
      EXPECT_FLOAT_EQ(got[k].score, want.score);
      EXPECT_EQ(got[k].box, want.box);
      ASSERT_EQ(got[k].mask.size(), size);
      cv::Mat want_mask = want.mask;
      if (want_mask.empty()) {  // box-only instances are written as their box
        want_mask = cv::Mat(size, CV_8UC1, cv::Scalar(0));
        want_mask(want.box).setTo(255);
      }
      EXPECT_EQ(cv::countNonZero((got[k].mask != 0) != (want_mask != 0)), 0) << "instance " << k;
    }
  }
}

TEST_F(MaskDirTest, HigherScoreWinsWhereMasksOverlap) {
  const cv::Size size(64, 48);
  const Timestamp t{1000000000};
  std::vector<Instance> in = {
      MakeInstance(0, "person", 0.4f, cv::Rect(0, 0, 30, 30), size, false),
      MakeInstance(0, "person", 0.8f, cv::Rect(20, 0, 30, 30), size, false)};
  WriteMasks(dir_.string(), {t}, {in}, size);
  const cv::Mat ids = cv::imread(MaskPngPath(dir_.string(), t), cv::IMREAD_UNCHANGED);
  EXPECT_EQ(cv::countNonZero(ids == 1), 20 * 30);
  EXPECT_EQ(cv::countNonZero(ids == 2), 30 * 30);
  EXPECT_TRUE(fs::exists(InstanceMaskPngPath(dir_.string(), t, 1))) << "the loser keeps its mask";
  EXPECT_FALSE(fs::exists(InstanceMaskPngPath(dir_.string(), t, 2)));
  const auto got = MaskDirSegmenter(dir_.string()).Segment(Frame(t.ToString()));
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(cv::countNonZero(got[0].mask), 30 * 30);
  EXPECT_EQ(cv::countNonZero(got[0].mask(cv::Rect(20, 0, 10, 30))), 10 * 30);
  EXPECT_EQ(cv::countNonZero(got[1].mask), 30 * 30);
}

// What `detslam segment` writes and `masks:DIR` replays must be the segmenter's own output:
// overlapping masks whole, scores to the last bit (the benchmarks replay dnn masks).
TEST_F(MaskDirTest, OverlappingMasksAndScoresReadBackExactly) {
  const cv::Size size(64, 48);
  const Timestamp t{1000000000};
  std::vector<Instance> in = {
      MakeInstance(0, "person", 0.123456791f, cv::Rect(0, 0, 40, 40), size, true),
      MakeInstance(0, "person", 0.987654328f, cv::Rect(25, 5, 30, 40), size, true),
      MakeInstance(0, "person", 0.5f, cv::Rect(10, 10, 10, 10), size, true)};  // inside both
  in[1].mask.at<uint8_t>(47, 0) = 1;  // any non-zero value is object
  WriteMasks(dir_.string(), {t}, {in}, size);
  const auto got = MaskDirSegmenter(dir_.string()).Segment(Frame(t.ToString()));
  ASSERT_EQ(got.size(), in.size());
  for (size_t k = 0; k < in.size(); ++k) {
    EXPECT_EQ(got[k].score, in[k].score) << "instance " << k;
    EXPECT_EQ(cv::countNonZero((got[k].mask != 0) != (in[k].mask != 0)), 0) << "instance " << k;
  }
}

TEST_F(MaskDirTest, BadInstanceMaskPngsAreNamed) {
  WriteList("1.0 1 0 person 0.5 0 0 8 8\n");
  const Timestamp t{1000000000};
  const std::string own = InstanceMaskPngPath(dir_.string(), t, 1);
  ASSERT_TRUE(cv::imwrite(own, cv::Mat(40, 64, CV_8UC1, cv::Scalar(255))));
  MaskDirSegmenter seg(dir_.string());
  std::string e = ErrorOf([&] { seg.Segment(Frame("1.0")); });
  EXPECT_NE(e.find(own), std::string::npos) << e;
  EXPECT_NE(e.find("64x40"), std::string::npos) << e;
  ASSERT_TRUE(cv::imwrite(own, cv::Mat(48, 64, CV_16UC1, cv::Scalar(1))));
  e = ErrorOf([&] { seg.Segment(Frame("1.0")); });
  EXPECT_NE(e.find("8-bit"), std::string::npos) << e;
  std::ofstream(own) << "not a png";
  e = ErrorOf([&] { seg.Segment(Frame("1.0")); });
  EXPECT_NE(e.find(own), std::string::npos) << e;
  ASSERT_TRUE(cv::imwrite(own, cv::Mat(48, 64, CV_8UC1, cv::Scalar(0))));
  const auto got = seg.Segment(Frame("1.0"));
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(cv::countNonZero(got[0].mask), 0) << "the own file wins over the (absent) id image";
}

TEST_F(MaskDirTest, ReadsTheSynthGeneratorsEightFieldLines) {
  WriteList(
      "# timestamp id class score x y w h\n1.000000 1 person 1 2 3 4 5\n"
      "1.000000 2 bicycle 1 10 10 2 2\n");
  cv::Mat ids(48, 64, CV_16UC1, cv::Scalar(0));
  ids(cv::Rect(2, 3, 4, 5)).setTo(1);
  ids(cv::Rect(10, 10, 2, 2)).setTo(2);
  ASSERT_TRUE(cv::imwrite((dir_ / "1.000000.png").string(), ids));
  const auto got = MaskDirSegmenter(dir_.string()).Segment(Frame("1.000000"));
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[0].class_id, 0);
  EXPECT_EQ(got[0].class_name, "person");
  EXPECT_EQ(cv::countNonZero(got[0].mask), 20);
  EXPECT_EQ(got[1].class_id, 1);
  EXPECT_EQ(cv::countNonZero(got[1].mask), 4);
}

TEST_F(MaskDirTest, EightBitPngAndBoxOnlyLines) {
  WriteList("1.0 1 0 person 0.5 0 0 8 8\n2.0 1 56 chair 0.7 5 5 10 10\n");
  cv::Mat ids(48, 64, CV_8UC1, cv::Scalar(0));
  ids(cv::Rect(0, 0, 8, 8)).setTo(1);
  ASSERT_TRUE(cv::imwrite((dir_ / "1.000000.png").string(), ids));
  MaskDirSegmenter seg(dir_.string());
  EXPECT_EQ(cv::countNonZero(seg.Segment(Frame("1.0"))[0].mask), 64);
  const auto chair = seg.Segment(Frame("2.0"));  // listed, no PNG: box only
  ASSERT_EQ(chair.size(), 1u);
  EXPECT_TRUE(chair[0].mask.empty());
  EXPECT_EQ(chair[0].box, cv::Rect(5, 5, 10, 10));
  EXPECT_TRUE(seg.Segment(Frame("3.0")).empty());
}

TEST_F(MaskDirTest, MalformedLinesNameFileAndLine) {
  const std::string list = (dir_ / "instances.txt").string();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"# c\n1.0 1 0 person 0.5 0 0\n", "fields"},
      {"# c\nabc 1 0 person 0.5 0 0 8 8\n", "timestamp"},
      {"# c\n1.0 0 0 person 0.5 0 0 8 8\n", "id"},
      {"# c\n1.0 1.5 0 person 0.5 0 0 8 8\n", "integer"},
      {"# c\n1.0 1 0 person 1.5 0 0 8 8\n", "score"},
      {"# c\n1.0 1 0 person 0.5 0 0 -8 8\n", "width"},
      {"1.0 1 0 person 0.5 0 0 8 8\n1.0 1 0 person 0.5 0 0 8 8\n", "duplicate"},
  };
  for (const auto& [text, what] : cases) {
    WriteList(text);
    const std::string e = ErrorOf([&] { MaskDirSegmenter seg(dir_.string()); });
    EXPECT_NE(e.find(list + ":2:"), std::string::npos) << text << " -> " << e;
    EXPECT_NE(e.find(what), std::string::npos) << text << " -> " << e;
  }
}

TEST_F(MaskDirTest, BadPngsAreNamed) {
  WriteList("1.0 1 0 person 0.5 0 0 8 8\n");
  const std::string png = (dir_ / "1.000000.png").string();
  cv::Mat ids(40, 64, CV_16UC1, cv::Scalar(0));
  ASSERT_TRUE(cv::imwrite(png, ids));
  MaskDirSegmenter seg(dir_.string());
  std::string e = ErrorOf([&] { seg.Segment(Frame("1.0")); });
  EXPECT_NE(e.find(png), std::string::npos) << e;
  EXPECT_NE(e.find("64x40"), std::string::npos) << e;
  ids = cv::Mat(48, 64, CV_16UC1, cv::Scalar(0));
  ids.at<uint16_t>(3, 3) = 7;
  ASSERT_TRUE(cv::imwrite(png, ids));
  e = ErrorOf([&] { seg.Segment(Frame("1.0")); });
  EXPECT_NE(e.find(png), std::string::npos) << e;
  EXPECT_NE(e.find("id 7"), std::string::npos) << e;
  std::ofstream(png) << "not a png";
  e = ErrorOf([&] { seg.Segment(Frame("1.0")); });
  EXPECT_NE(e.find(png), std::string::npos) << e;
}

TEST_F(MaskDirTest, MissingFolderOrListIsAnInputError) {
  const std::string e = ErrorOf([&] { MaskDirSegmenter seg(dir_.string()); });
  EXPECT_NE(e.find((dir_ / "instances.txt").string()), std::string::npos) << e;
  EXPECT_THROW(MaskDirSegmenter((dir_ / "nope").string()), InputError);
}

}  // namespace
}  // namespace detslam
