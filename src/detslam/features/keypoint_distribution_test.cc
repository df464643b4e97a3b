#include "detslam/features/keypoint_distribution.h"

#include <gtest/gtest.h>

#include <set>
#include <vector>

#include "detslam/core/rng.h"

namespace detslam {
namespace {

TEST(DistributeQuadtreeTest, ReturnsTargetCountOfDistinctIndices) {
  Rng rng(3);
  std::vector<cv::KeyPoint> kps;
  for (int i = 0; i < 2000; ++i) {
    kps.emplace_back(cv::Point2f(rng.UniformInt(0, 639), rng.UniformInt(0, 479)), 7.f, -1.f,
                     static_cast<float>(rng.UniformInt(7, 100)));
  }
  for (int target : {1, 37, 150, 600}) {
    const std::vector<size_t> kept = DistributeQuadtree(kps, 0, 640, 0, 480, target);
    EXPECT_EQ(kept.size(), static_cast<size_t>(target));
    EXPECT_EQ(std::set<size_t>(kept.begin(), kept.end()).size(), kept.size());
  }
  // Fewer keypoints than the target: all of them.
  EXPECT_EQ(DistributeQuadtree({kps.begin(), kps.begin() + 10}, 0, 640, 0, 480, 50).size(), 10u);
  EXPECT_TRUE(DistributeQuadtree(kps, 0, 640, 0, 480, 0).empty());
}

TEST(DistributeQuadtreeTest, SpreadsBudgetBeyondDenseCluster) {
  Rng rng(4);
  std::vector<cv::KeyPoint> kps;
  // 800 strong corners packed in a 40 x 40 corner, 60 weak ones scattered over the image.
  for (int i = 0; i < 800; ++i) {
    kps.emplace_back(cv::Point2f(rng.UniformInt(0, 39), rng.UniformInt(0, 39)), 7.f, -1.f, 90.f);
  }
  for (int i = 0; i < 60; ++i) {
    kps.emplace_back(cv::Point2f(rng.UniformInt(100, 639), rng.UniformInt(100, 479)), 7.f, -1.f,
                     10.f);
  }
  const std::vector<size_t> kept = DistributeQuadtree(kps, 0, 640, 0, 480, 100);
  int scattered = 0;
  for (size_t i : kept) scattered += i >= 800;
  // Taking the strongest 100 would keep none of the weak ones; the quadtree keeps most.
  EXPECT_GE(scattered, 50);
}

TEST(DistributeQuadtreeTest, KeepsStrongestPerNode) {
  // Two tight pairs far apart; with target 2 each pair becomes one node and keeps its best.
  std::vector<cv::KeyPoint> kps = {{cv::Point2f(10, 10), 7.f, -1.f, 20.f},
                                   {cv::Point2f(11, 10), 7.f, -1.f, 50.f},
                                   {cv::Point2f(600, 400), 7.f, -1.f, 90.f},
                                   {cv::Point2f(601, 401), 7.f, -1.f, 30.f}};
  EXPECT_EQ(DistributeQuadtree(kps, 0, 640, 0, 480, 2), (std::vector<size_t>{1, 2}));
}

}  // namespace
}  // namespace detslam
