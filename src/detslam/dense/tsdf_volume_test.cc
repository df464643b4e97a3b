#include "detslam/dense/tsdf_volume.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "detslam/core/check.h"
#include "detslam/dense/dense_test_util.h"

namespace detslam {
namespace {

using dense_test::CoarseOptions;
using dense_test::PlaneDepth;
using dense_test::SmallCamera;

Rigid3d ShiftedX(double x) {
  return Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(x, 0, 0));
}

TEST(TsdfVolume, FrontoParallelWallIsReadOutOnThePlaneWithItsColourAndNormal) {
  const PinholeCamera cam = SmallCamera();
  TsdfOptions o = CoarseOptions();
  TsdfVolume volume(o);
  const cv::Mat bgr(cam.height, cam.width, CV_8UC3, cv::Scalar(10, 20, 200));
  for (const double x : {-0.05, 0.0, 0.05}) {
    // The camera moves along x; the wall stays at world z = 2.
    volume.Integrate(cam, ShiftedX(x), PlaneDepth(cam, 2.0, 0.0), bgr, cv::Mat());
  }
  EXPECT_EQ(volume.integrated_images(), 3);
  const std::vector<DensePoint> points = volume.ExtractSurfacePoints();
  ASSERT_GT(points.size(), 500u);  // the wall is about 2.3 x 1.7 m: thousands of 2 cm cells
  for (const DensePoint& p : points) {
    ASSERT_NEAR(p.position.z(), 2.0, 0.005) << p.position.transpose();
    ASSERT_NEAR(p.normal.z(), -1.0, 1e-3);  // towards the camera
    ASSERT_EQ(p.rgb[0], 200);               // r g b of the b g r image
    ASSERT_EQ(p.rgb[1], 20);
    ASSERT_EQ(p.rgb[2], 10);
  }
}

TEST(TsdfVolume, SlantedPlaneWithinAQuarterVoxel) {
  const PinholeCamera cam = SmallCamera();
  TsdfOptions o = CoarseOptions();
  TsdfVolume volume(o);
  for (const double x : {-0.04, 0.0, 0.04}) {
    // World plane z = 2 + 0.5 x, seen from cameras shifted along x: in each camera's frame the
    // plane is z = (2 + 0.5 x_cam_origin) + 0.5 x.
    volume.Integrate(cam, ShiftedX(x), PlaneDepth(cam, 2.0 + 0.5 * x, 0.5), cv::Mat(), cv::Mat());
  }
  const std::vector<DensePoint> points = volume.ExtractSurfacePoints();
  ASSERT_GT(points.size(), 500u);
  const Eigen::Vector3d n = Eigen::Vector3d(-0.5, 0, 1).normalized();
  double worst = 0;
  size_t normal_ok = 0;
  for (const DensePoint& p : points) {
    const Eigen::Vector3d q = p.position.cast<double>();
    worst = std::max(worst, std::abs(n.dot(q) - n.dot(Eigen::Vector3d(0, 0, 2))));
    ASSERT_GT(p.normal.cast<double>().dot(-n), 0.85);  // at worst an axis next to the normal
    normal_ok += p.normal.cast<double>().dot(-n) > 0.97;  // projective distances bend it off-axis
    ASSERT_EQ(p.rgb[0], 128);  // no colour image: grey
  }
  EXPECT_LT(worst, 0.005);
  EXPECT_GT(normal_ok, points.size() * 95 / 100);  // the rest lie on the edge of what was seen
}

TEST(TsdfVolume, ExcludedPixelsAreNeverFused) {
  const PinholeCamera cam = SmallCamera();
  TsdfOptions o = CoarseOptions();
  o.carve = false;
  TsdfVolume volume(o);
  cv::Mat exclude(cam.height, cam.width, CV_8UC1, cv::Scalar(0));
  exclude.colRange(0, cam.width / 2).setTo(255);  // the left half: x < 0 in each camera
  for (const double x : {-0.05, 0.0, 0.05})
    volume.Integrate(cam, ShiftedX(x), PlaneDepth(cam, 2.0, 0.0), cv::Mat(), exclude);
  const std::vector<DensePoint> points = volume.ExtractSurfacePoints();
  ASSERT_GT(points.size(), 200u);
  for (const DensePoint& p : points) ASSERT_GT(p.position.x(), -0.05 - 0.03);
}

// A box in front of the wall in the first frames, gone later (a person not masked): with carving
// the later views of the wall through where it stood remove it; without carving it stays.
TEST(TsdfVolume, CarvingRemovesASurfaceLaterSeenThrough) {
  const PinholeCamera cam = SmallCamera();
  cv::Mat with_box = PlaneDepth(cam, 2.0, 0.0);
  with_box(cv::Rect(60, 40, 40, 40)).setTo(1.0f);
  const cv::Mat wall = PlaneDepth(cam, 2.0, 0.0);
  for (const bool carve : {true, false}) {
    TsdfOptions o = CoarseOptions();
    o.carve = carve;
    TsdfVolume volume(o);
    for (int i = 0; i < 4; ++i) volume.Integrate(cam, ShiftedX(0.01 * i), with_box, cv::Mat(), cv::Mat());
    int near_box = 0;
    for (const DensePoint& p : volume.ExtractSurfacePoints()) near_box += p.position.z() < 1.5f;
    ASSERT_GT(near_box, 50) << "the box is fused";
    for (int i = 0; i < 12; ++i) volume.Integrate(cam, ShiftedX(0.01 * i), wall, cv::Mat(), cv::Mat());
    near_box = 0;
    int on_wall = 0;
    for (const DensePoint& p : volume.ExtractSurfacePoints()) {
      near_box += p.position.z() < 1.5f;
      on_wall += std::abs(p.position.z() - 2.0f) < 0.01f;
    }
    if (carve) {
      EXPECT_EQ(near_box, 0);
    } else {
      EXPECT_GT(near_box, 50);
    }
    EXPECT_GT(on_wall, 1000);
  }
}

TEST(TsdfVolume, VoxelsSeenFewerThanMinWeightTimesAreNotReadOut) {
  const PinholeCamera cam = SmallCamera();
  TsdfOptions o = CoarseOptions();
  o.min_weight = 2;
  TsdfVolume volume(o);
  volume.Integrate(cam, Rigid3d(), PlaneDepth(cam, 2.0, 0.0), cv::Mat(), cv::Mat());
  EXPECT_TRUE(volume.ExtractSurfacePoints().empty());
  volume.Integrate(cam, Rigid3d(), PlaneDepth(cam, 2.0, 0.0), cv::Mat(), cv::Mat());
  EXPECT_FALSE(volume.ExtractSurfacePoints().empty());
  EXPECT_GT(volume.num_blocks(), 0u);
  EXPECT_GT(volume.MemoryBytes(), volume.num_blocks() * 4096);
}

TEST(TsdfVolume, DepthOutsideTheRangeIsIgnored) {
  const PinholeCamera cam = SmallCamera();
  TsdfOptions o = CoarseOptions();
  o.min_weight = 1;
  o.max_depth_m = 1.5;
  TsdfVolume volume(o);
  volume.Integrate(cam, Rigid3d(), PlaneDepth(cam, 2.0, 0.0), cv::Mat(), cv::Mat());
  EXPECT_EQ(volume.num_blocks(), 0u);
  EXPECT_TRUE(volume.ExtractSurfacePoints().empty());
}

TEST(TsdfVolume, WrongImagesAndOptionsAreErrors) {
  const PinholeCamera cam = SmallCamera();
  TsdfVolume volume{TsdfOptions()};
  EXPECT_THROW(volume.Integrate(cam, Rigid3d(), cv::Mat(10, 10, CV_32FC1, cv::Scalar(1)), cv::Mat(),
                                cv::Mat()),
               InputError);
  EXPECT_THROW(volume.Integrate(cam, Rigid3d(), PlaneDepth(cam, 2, 0),
                                cv::Mat(cam.height, cam.width, CV_8UC1), cv::Mat()),
               InputError);
  EXPECT_THROW(volume.Integrate(cam, Rigid3d(), PlaneDepth(cam, 2, 0), cv::Mat(),
                                cv::Mat(cam.height, cam.width, CV_16UC1)),
               InputError);
  std::string error;
  TsdfOptions o;
  EXPECT_TRUE(o.Check(&error)) << error;
  o.truncation_m = 0.005;
  EXPECT_FALSE(o.Check(&error));
  EXPECT_THAT(error, ::testing::HasSubstr("truncation"));
  o = TsdfOptions();
  o.voxel_m = 0;
  EXPECT_FALSE(o.Check(&error));
  o = TsdfOptions();
  o.min_weight = 100;
  EXPECT_FALSE(o.Check(&error));
}

TEST(TsdfVolume, UndistortionKeepsAConstantDepthAndZeroesTheCoefficients) {
  PinholeCamera cam = SmallCamera();
  const cv::Mat depth = PlaneDepth(cam, 2.0, 0.0);
  UndistortedImages same = UndistortForFusion(cam, depth, cv::Mat(), cv::Mat());
  EXPECT_EQ(same.depth_m.data, depth.data);  // no distortion: the same image
  cam.k1 = 0.2;
  cam.k2 = -0.1;
  const UndistortedImages u = UndistortForFusion(cam, depth, cv::Mat(), cv::Mat());
  EXPECT_FALSE(u.camera.HasDistortion());
  EXPECT_EQ(u.depth_m.at<float>(cam.height / 2, cam.width / 2), 2.0f);
  EXPECT_NE(u.depth_m.data, depth.data);
}

}  // namespace
}  // namespace detslam
