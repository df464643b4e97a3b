#include "detslam/dense/dense_fusion.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgproc.hpp>

#include "detslam/core/check.h"
#include "detslam/dense/dense_test_util.h"
#include "detslam/io/ply.h"
#include "support/cli_runner.h"

namespace detslam {
namespace {
namespace fs = std::filesystem;

// Frames of a wall at z = 2 m seen from the origin, each 1/30 s apart; frame `bad` cannot be read.
class WallSource : public RgbdSource {
 public:
  explicit WallSource(size_t n, size_t bad = static_cast<size_t>(-1)) : n_(n), bad_(bad) {}
  size_t size() const override { return n_; }
  Timestamp stamp(size_t i) const override { return Timestamp::FromSeconds(100.0 + i / 30.0); }
  RgbdImages Load(size_t i, const PinholeCamera& camera) const override {
    if (i == bad_) throw InputError("frame" + std::to_string(i) + ".png", 0, "corrupt");
    RgbdImages images;
    images.depth_m = cv::Mat(camera.height, camera.width, CV_32FC1, cv::Scalar(2.0f));
    images.bgr = cv::Mat(camera.height, camera.width, CV_8UC3, cv::Scalar(0, 255, 0));
    cv::cvtColor(images.bgr, images.gray, cv::COLOR_BGR2GRAY);
    return images;
  }
  const std::string& name() const override { return name_; }
  std::string groundtruth_path() const override { return ""; }

 private:
  size_t n_, bad_;
  std::string name_ = "wall";
};

using dense_test::CoarseOptions;
using dense_test::SmallCamera;

cv::Mat LeftHalfMask(const PinholeCamera& c) {
  cv::Mat m(c.height, c.width, CV_8UC1, cv::Scalar(0));
  m.colRange(0, c.width / 2).setTo(255);
  return m;
}

TEST(DenseFusion, MatchKeyframesByStampWithMasksAndCountsStrangers) {
  const WallSource source(10);
  Trajectory poses;
  poses.push_back({source.stamp(2), Rigid3d()});
  poses.push_back({Timestamp::FromSeconds(5.0), Rigid3d()});  // not a frame of the source
  poses.push_back({source.stamp(7), Rigid3d()});
  KeyframeMasks masks;
  masks[7] = EncodeKeyframeMask(LeftHalfMask(SmallCamera()));
  masks[3] = "unused";
  size_t unmatched = 0;
  const std::vector<DenseKeyframe> kfs = MatchKeyframes(source, poses, masks, &unmatched);
  ASSERT_EQ(kfs.size(), 2u);
  EXPECT_EQ(unmatched, 1u);
  EXPECT_EQ(kfs[0].frame, 2u);
  EXPECT_TRUE(kfs[0].exclude_png.empty());
  EXPECT_EQ(kfs[1].frame, 7u);
  EXPECT_EQ(kfs[1].exclude_png, masks[7]);
}

TEST(DenseFusion, MaskedPixelsStayOutAndUnreadableKeyframesAreSkipped) {
  const PinholeCamera cam = SmallCamera();
  const WallSource source(6, /*bad=*/4);
  std::vector<DenseKeyframe> kfs;
  for (size_t i = 0; i < 6; ++i) {
    DenseKeyframe kf;
    kf.frame = i;
    kf.exclude_png = EncodeKeyframeMask(LeftHalfMask(cam));
    kfs.push_back(kf);
  }
  DenseMapStats stats;
  size_t progress_calls = 0;
  const TsdfVolume volume = FuseKeyframes(source, cam, kfs, CoarseOptions(), &stats,
                                          [&](size_t, size_t total) {
                                            ++progress_calls;
                                            EXPECT_EQ(total, 6u);
                                          });
  EXPECT_EQ(stats.keyframes, 5u);
  EXPECT_EQ(stats.unreadable, 1u);
  EXPECT_EQ(progress_calls, 5u);
  EXPECT_GT(stats.blocks, 0u);
  const std::string path = testing::TempPath("dense_half.ply");
  WriteDenseMap(volume, path, &stats);
  const PointCloud cloud = ReadPointCloudPly(path);
  ASSERT_EQ(cloud.points.size(), stats.points);
  ASSERT_GT(cloud.points.size(), 300u);
  ASSERT_EQ(cloud.normals.size(), cloud.points.size());
  for (size_t i = 0; i < cloud.points.size(); ++i) {
    ASSERT_GT(cloud.points[i].x(), -0.03);  // the masked left half (x < 0) is not in the map
    ASSERT_NEAR(cloud.points[i].z(), 2.0, 0.005);
    ASSERT_EQ(cloud.colors[i], (Eigen::Matrix<uint8_t, 3, 1>(0, 255, 0)));
  }
  fs::remove(path);
}

TEST(DenseFusion, AMaskOfAnotherSizeIsAnError) {
  const PinholeCamera cam = SmallCamera();
  const WallSource source(1);
  DenseKeyframe kf;
  kf.exclude_png = EncodeKeyframeMask(cv::Mat(10, 10, CV_8UC1, cv::Scalar(0)));
  EXPECT_THAT([&] { FuseKeyframes(source, cam, {kf}, CoarseOptions(), nullptr); },
              ::testing::ThrowsMessage<InputError>(::testing::HasSubstr("mask of frame 0")));
}

TEST(DenseFusion, KeyframeMasksRoundTripAndReplaceAnEarlierRunsMasks) {
  const std::string dir = testing::TempDir("keyframe_masks");
  KeyframeMasks first;
  first[3] = EncodeKeyframeMask(LeftHalfMask(SmallCamera()));
  first[12] = EncodeKeyframeMask(cv::Mat(4, 4, CV_8UC1, cv::Scalar(255)));
  WriteKeyframeMasks(dir, first);
  EXPECT_TRUE(fs::exists(KeyframeMaskPath(dir, 3)));
  EXPECT_EQ(fs::path(KeyframeMaskPath(dir, 12)).filename(), "000012.png");
  EXPECT_EQ(ReadKeyframeMasks(dir), first);
  { std::ofstream(fs::path(dir) / "notes.txt") << "kept\n"; }
  KeyframeMasks second;
  second[5] = first[12];
  WriteKeyframeMasks(dir, second);
  EXPECT_EQ(ReadKeyframeMasks(dir), second);  // 3 and 12 are gone
  EXPECT_TRUE(fs::exists(fs::path(dir) / "notes.txt"));
  EXPECT_TRUE(ReadKeyframeMasks(dir + "/missing").empty());
  { std::ofstream(KeyframeMaskPath(dir, 7), std::ios::binary) << "not a png"; }
  EXPECT_THAT([&] { ReadKeyframeMasks(dir); },
              ::testing::ThrowsMessage<InputError>(::testing::HasSubstr(KeyframeMaskPath(dir, 7))));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace detslam
