// LabelMovers on a hand-made frame: static keypoints whose points reproject exactly, a cluster of
// keypoints whose points moved (a mover), one isolated keypoint whose point moved (a mismatch),
// and an unmatched keypoint beside the cluster at its depth.
#include "detslam/dynamic/mover_check.h"

#include <gtest/gtest.h>

namespace detslam {
namespace {

struct Scene {
  Frame frame;
  std::vector<std::optional<Eigen::Vector3d>> points;
  std::vector<size_t> cluster;
  size_t isolated = 0;
  size_t unmatched = 0;
};

Scene MakeScene(const PinholeCamera& camera) {
  std::vector<cv::KeyPoint> kps;
  std::vector<float> depth;
  auto add = [&](float x, float y, float d) {
    kps.emplace_back(x, y, 31.0f, 0.0f, 1.0f, 0);
    depth.push_back(d);
    return kps.size() - 1;
  };
  Scene s;
  for (int y = 20; y < 480; y += 40) {
    for (int x = 20; x < 640; x += 40) add(static_cast<float>(x), static_cast<float>(y), 3.0f);
  }
  for (int k = 0; k < 6; ++k) s.cluster.push_back(add(300.0f + 6 * k, 250.0f, 1.5f));
  s.isolated = add(590.0f, 450.0f, 3.0f);
  s.unmatched = add(300.0f, 262.0f, 1.5f);
  s.frame.index = 7;
  s.frame.cam_from_world = Rigid3d::Identity();
  s.frame.features = BuildFrameFeatures(
      camera, kps, cv::Mat::zeros(static_cast<int>(kps.size()), 32, CV_8UC1), depth);
  const FrameFeatures& f = *s.frame.features;
  s.frame.landmarks.assign(f.size(), kNoLandmark);
  s.points.assign(f.size(), std::nullopt);
  for (size_t i = 0; i < f.size(); ++i) {
    if (i == s.unmatched) continue;
    s.frame.landmarks[i] = static_cast<LandmarkId>(i);
    s.points[i] = camera.Unproject(f.undist[i], f.depth[i]);
  }
  // The person walked 10 cm to the right since its points were mapped: ~36 px at 1.5 m.
  for (size_t i : s.cluster) *s.points[i] -= Eigen::Vector3d(0.1, 0, 0);
  *s.points[s.isolated] -= Eigen::Vector3d(0.2, 0, 0);
  s.frame.labels.assign(f.size(), KeypointLabel::kStatic);
  return s;
}

TEST(LabelMovers, LabelsAConfirmedClusterAndItsUnmatchedNeighbourNotAnIsolatedOutlier) {
  const PinholeCamera camera;
  Scene s = MakeScene(camera);
  MoverCheckOptions options;
  const int labelled = LabelMovers(camera, ScaleInfo::Geometric(1.2, 8), options, s.frame, s.points,
                                   nullptr, &s.frame.labels);
  for (size_t i : s.cluster) EXPECT_EQ(s.frame.labels[i], KeypointLabel::kGeometric) << i;
  EXPECT_EQ(s.frame.labels[s.unmatched], KeypointLabel::kGeometric);
  EXPECT_EQ(s.frame.labels[s.isolated], KeypointLabel::kStatic);
  EXPECT_EQ(labelled, static_cast<int>(s.cluster.size()) + 1);
  int static_labelled = 0;
  for (size_t i = 0; i < s.cluster.front(); ++i)
    static_labelled += s.frame.labels[i] != KeypointLabel::kStatic;
  EXPECT_EQ(static_labelled, 0);
}

TEST(LabelMovers, NeedsEnoughFlaggedNeighboursAndKeepsOtherLabels) {
  const PinholeCamera camera;
  Scene s = MakeScene(camera);
  MoverCheckOptions options;
  options.min_cluster = 6;  // the cluster has 6 keypoints: each has only 5 flagged neighbours
  s.frame.labels[s.cluster[0]] = KeypointLabel::kDynamicMask;
  EXPECT_EQ(LabelMovers(camera, ScaleInfo::Geometric(1.2, 8), options, s.frame, s.points, nullptr,
                        &s.frame.labels),
            0);
  EXPECT_EQ(s.frame.labels[s.cluster[0]], KeypointLabel::kDynamicMask);
  for (size_t k = 1; k < s.cluster.size(); ++k)
    EXPECT_EQ(s.frame.labels[s.cluster[k]], KeypointLabel::kStatic);
}

}  // namespace
}  // namespace detslam
