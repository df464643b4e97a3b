#include "detslam/map/map.h"

#include <gtest/gtest.h>

#include "detslam/map/map_test_util.h"

namespace detslam {
namespace {

ScaleInfo TestScale() { return ScaleInfo::Geometric(1.2, 8); }

KeyFrame MakeKeyFrame(size_t n, double x) {
  KeyFrame kf;
  kf.features = map_test::RowFeatures(n, static_cast<uint8_t>(x * 10));
  kf.cam_from_world = Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-x, 0, 0));
  return kf;
}

TEST(ScaleInfo, GeometricPyramid) {
  const ScaleInfo s = ScaleInfo::Geometric(1.2, 8);
  ASSERT_EQ(s.num_levels(), 8);
  EXPECT_DOUBLE_EQ(s.scale_factors[0], 1.0);
  EXPECT_DOUBLE_EQ(s.scale_factors[2], 1.44);
  EXPECT_DOUBLE_EQ(s.level_sigma2[2], 1.44 * 1.44);
  EXPECT_DOUBLE_EQ(s.inv_level_sigma2[2], 1.0 / (1.44 * 1.44));
  EXPECT_DOUBLE_EQ(s.log_scale_factor, std::log(1.2));
}

TEST(Map, ObservationsAreMirroredAndCovisibilityCountsSharedPoints) {
  Map map(TestScale());
  const KeyFrameId a = map.AddKeyFrame(MakeKeyFrame(5, 0));
  const KeyFrameId b = map.AddKeyFrame(MakeKeyFrame(5, 1));
  for (size_t i = 0; i < 3; ++i) {
    const LandmarkId lm = map.AddLandmark(Eigen::Vector3d(i, 0, 2), a);
    map.AddObservation(lm, a, i);
    map.AddObservation(lm, b, i + 1);
  }
  map.UpdateConnections(b);
  EXPECT_EQ(map.keyframe(a).covisibility.at(b), 3);
  EXPECT_EQ(map.keyframe(b).covisibility.at(a), 3);
  EXPECT_EQ(map.keyframe(b).parent, a);
  EXPECT_EQ(map.TrackedLandmarks(a, 2), 3);
  const LandmarkId first = map.keyframe(a).landmarks[0];
  map.EraseObservation(first, b);
  EXPECT_EQ(map.keyframe(b).landmarks[1], kNoLandmark);
  EXPECT_EQ(map.landmark(first).observations.size(), 1u);
  map.EraseObservation(first, a);  // last observation removes the landmark
  EXPECT_FALSE(map.HasLandmark(first));
  EXPECT_EQ(map.keyframe(a).landmarks[0], kNoLandmark);
}

TEST(Map, ReplaceLandmarkMovesObservations) {
  Map map(TestScale());
  const KeyFrameId a = map.AddKeyFrame(MakeKeyFrame(3, 0));
  const KeyFrameId b = map.AddKeyFrame(MakeKeyFrame(3, 1));
  const LandmarkId l1 = map.AddLandmark(Eigen::Vector3d(0, 0, 2), a);
  const LandmarkId l2 = map.AddLandmark(Eigen::Vector3d(0, 0, 2.01), b);
  map.AddObservation(l1, a, 0);
  map.AddObservation(l2, b, 2);
  map.ReplaceLandmark(l2, l1);
  EXPECT_FALSE(map.HasLandmark(l2));
  EXPECT_EQ(map.keyframe(b).landmarks[2], l1);
  EXPECT_EQ(map.landmark(l1).observations.size(), 2u);
}

TEST(Map, LookupsByIdFollowErasureCopiesAndMoves) {
  Map map(TestScale());
  const KeyFrameId a = map.AddKeyFrame(MakeKeyFrame(3, 0));
  const KeyFrameId b = map.AddKeyFrame(MakeKeyFrame(3, 1));
  const LandmarkId l1 = map.AddLandmark(Eigen::Vector3d(0, 0, 2), a);
  const LandmarkId l2 = map.AddLandmark(Eigen::Vector3d(1, 0, 2), b);
  map.AddObservation(l1, a, 0);
  map.AddObservation(l2, b, 1);
  EXPECT_FALSE(map.HasLandmark(kNoLandmark));
  EXPECT_FALSE(map.HasLandmark(l2 + 1));  // never made
  EXPECT_FALSE(map.HasKeyFrame(kNoKeyFrame));
  // A copy has its own elements: changing or erasing in it leaves the original alone.
  Map copy = map;
  copy.landmark(l1).position.x() = 5;
  copy.EraseLandmark(l2);
  copy.EraseKeyFrame(b);
  EXPECT_FALSE(copy.HasLandmark(l2));
  EXPECT_FALSE(copy.HasKeyFrame(b));
  EXPECT_TRUE(map.HasLandmark(l2));
  EXPECT_TRUE(map.HasKeyFrame(b));
  EXPECT_EQ(map.landmark(l1).position.x(), 0);
  EXPECT_EQ(copy.landmark(l1).position.x(), 5);
  // New ids continue after the copied ones.
  EXPECT_EQ(copy.AddLandmark(Eigen::Vector3d::Zero(), a), l2 + 1);
  EXPECT_TRUE(copy.HasLandmark(l2 + 1));
  EXPECT_FALSE(map.HasLandmark(l2 + 1));
  // A moved map keeps its lookups.
  Map moved = std::move(copy);
  EXPECT_EQ(moved.landmark(l1).position.x(), 5);
  EXPECT_EQ(moved.keyframe(a).landmarks[0], l1);
  map = moved;  // copy assignment
  EXPECT_FALSE(map.HasKeyFrame(b));
  EXPECT_EQ(map.landmark(l1).position.x(), 5);
}

TEST(Map, EraseKeyFrameReparentsChildrenAndDropsObservations) {
  Map map(TestScale());
  const KeyFrameId a = map.AddKeyFrame(MakeKeyFrame(4, 0));
  const KeyFrameId b = map.AddKeyFrame(MakeKeyFrame(4, 1));
  const KeyFrameId c = map.AddKeyFrame(MakeKeyFrame(4, 2));
  for (size_t i = 0; i < 4; ++i) {
    const LandmarkId lm = map.AddLandmark(Eigen::Vector3d(i, 0, 3), a);
    map.AddObservation(lm, a, i);
    map.AddObservation(lm, b, i);
    if (i < 2) map.AddObservation(lm, c, i);
  }
  map.UpdateConnections(b);
  map.keyframe(c).parent = b;
  map.keyframe(b).children.insert(c);
  map.EraseKeyFrame(b);
  EXPECT_FALSE(map.HasKeyFrame(b));
  EXPECT_EQ(map.keyframe(c).parent, a);
  for (const auto& [id, lm] : map.landmarks()) {
    (void)id;
    EXPECT_EQ(lm.observations.count(b), 0u);
  }
  map.EraseKeyFrame(a);  // the first keyframe is the map origin and is never erased
  EXPECT_TRUE(map.HasKeyFrame(a));
}

TEST(Map, DistanceBoundsAndScalePrediction) {
  Map map(TestScale());
  const KeyFrameId a = map.AddKeyFrame(MakeKeyFrame(1, 0));
  const LandmarkId lm = map.AddLandmark(Eigen::Vector3d(0, 0, 2), a);
  map.AddObservation(lm, a, 0);
  map.UpdateLandmarkGeometry(lm);
  const Landmark& l = map.landmark(lm);
  EXPECT_NEAR(l.max_distance, 2.0, 1e-12);  // level 0
  EXPECT_NEAR(l.min_distance, 2.0 / std::pow(1.2, 7), 1e-12);
  EXPECT_EQ(l.PredictScale(2.0, map.scale()), 0);
  EXPECT_EQ(l.PredictScale(2.0 / 1.3, map.scale()), 2);  // ceil(log(1.3) / log(1.2)) = 2
  EXPECT_NEAR(l.normal.z(), 1.0, 1e-12);
}

}  // namespace
}  // namespace detslam
