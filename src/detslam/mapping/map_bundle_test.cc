#include "detslam/mapping/map_bundle.h"

#include <gtest/gtest.h>

namespace detslam {
namespace {

std::shared_ptr<FrameFeatures> TwoKeypoints() {
  auto f = std::make_shared<FrameFeatures>();
  for (int i = 0; i < 2; ++i) {
    f->keypoints.emplace_back(100.0f + 50 * i, 100.0f, 31.0f, 0.0f, 1.0f, 0);
    f->undist.emplace_back(100.0 + 50 * i, 100.0);
    f->depth.push_back(2.0f);
    f->u_right.push_back(80.0f);
  }
  f->descriptors = cv::Mat(2, 32, CV_8UC1, cv::Scalar(7));
  return f;
}

KeyFrameId AddKeyFrameAt(Map* map, double x) {
  KeyFrame kf;
  kf.features = TwoKeypoints();
  kf.cam_from_world = Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-x, 0, 0));
  return map->AddKeyFrame(std::move(kf));
}

// Keyframes and landmarks created while a global bundle was being solved follow the correction of
// their spanning-tree parent and reference keyframe.
TEST(PropagateBundleCorrection, NewcomersMoveWithTheirParentAndReference) {
  Map map(ScaleInfo::Geometric(1.2, 8));
  const KeyFrameId k0 = AddKeyFrameAt(&map, 0.0);
  const KeyFrameId k1 = AddKeyFrameAt(&map, 1.0);
  const LandmarkId old_point = map.AddLandmark(Eigen::Vector3d(1, 0, 2), k1);
  map.AddObservation(old_point, k0, 0);
  map.AddObservation(old_point, k1, 0);
  const LandmarkId shared = map.AddLandmark(Eigen::Vector3d(1.5, 0, 2), k1);
  map.AddObservation(shared, k1, 1);
  map.UpdateConnections(k1);
  const MapBundle bundle = BuildMapBundle(map, {k0, k1}, {});
  ASSERT_EQ(bundle.problem.poses.size(), 2u);

  // Meanwhile: keyframe 2, child of 1, and a landmark it made.
  const KeyFrameId k2 = AddKeyFrameAt(&map, 2.0);
  const LandmarkId new_point = map.AddLandmark(Eigen::Vector3d(2, 0.5, 2), k2);
  map.AddObservation(new_point, k2, 1);
  map.AddObservation(shared, k2, 0);
  map.UpdateConnections(k2);
  ASSERT_EQ(map.keyframe(k2).parent, k1);

  // The solved bundle moved keyframe 1 by 10 cm along y.
  MapBundle solved = bundle;
  solved.problem.poses[1].cam_from_world =
      Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-1.0, -0.1, 0));
  BundleSummary summary;
  summary.usable = true;
  summary.outlier.assign(solved.problem.observations.size(), false);
  std::map<KeyFrameId, Rigid3d> before;
  for (const auto& [id, kf] : map.keyframes()) before[id] = kf.cam_from_world;
  ApplyMapBundle(solved, summary, &map);
  PropagateBundleCorrection(solved, before, &map);

  EXPECT_NEAR(map.keyframe(k1).Center().y(), 0.1, 1e-12);
  EXPECT_NEAR(map.keyframe(k2).Center().x(), 2.0, 1e-12);  // moved with keyframe 1
  EXPECT_NEAR(map.keyframe(k2).Center().y(), 0.1, 1e-12);
  EXPECT_NEAR(map.landmark(new_point).position.y(), 0.6, 1e-12);  // with keyframe 2
  EXPECT_NEAR(map.keyframe(k0).Center().y(), 0.0, 1e-12);         // the anchor stays
}

}  // namespace
}  // namespace detslam
