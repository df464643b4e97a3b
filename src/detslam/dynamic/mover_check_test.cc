// LabelMovers on a hand-made frame: static keypoints whose points reproject exactly, a cluster of
// keypoints whose points moved (a mover), one isolated keypoint whose point moved (a mismatch),
// and an unmatched keypoint beside the cluster at its depth.
#include "detslam/dynamic/mover_check.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>

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
  std::vector<size_t> confirmed;
  const int labelled = LabelMovers(camera, ScaleInfo::Geometric(1.2, 8), options, s.frame, s.points,
                                   nullptr, &s.frame.labels, &confirmed);
  EXPECT_EQ(confirmed, s.cluster);  // the seeds: not the unmatched neighbour
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


TEST(LabelMovers, WithCoherenceOnlyNeighboursThatMovedAlikeConfirm) {
  const PinholeCamera camera;
  const ScaleInfo scale = ScaleInfo::Geometric(1.2, 8);
  MoverCheckOptions options;
  options.coherence = 0.5;
  // The mover of MakeScene: every point shifted alike, confirmed as without coherence.
  Scene mover = MakeScene(camera);
  std::vector<size_t> confirmed;
  LabelMovers(camera, scale, options, mover.frame, mover.points, nullptr, &mover.frame.labels,
              &confirmed);
  EXPECT_EQ(confirmed, mover.cluster);
  // Mismatches: the cluster's points off by as much but each in another direction (as the
  // associations the pose optimiser rejects on a textured static scene).
  Scene mismatched = MakeScene(camera);
  for (size_t k = 0; k < mismatched.cluster.size(); ++k) {
    const double a = 2.0 * M_PI * static_cast<double>(k) / static_cast<double>(mismatched.cluster.size());
    *mismatched.points[mismatched.cluster[k]] =
        camera.Unproject(mismatched.frame.features->undist[mismatched.cluster[k]], 1.5f) +
        0.1 * Eigen::Vector3d(std::cos(a), std::sin(a), 0);
  }
  Scene without = mismatched;
  EXPECT_EQ(LabelMovers(camera, scale, options, mismatched.frame, mismatched.points, nullptr,
                        &mismatched.frame.labels, &confirmed),
            0);
  EXPECT_TRUE(confirmed.empty());
  // Without coherence the same mismatches make a mover: what the option must tell apart.
  LabelMovers(camera, scale, MoverCheckOptions(), without.frame, without.points, nullptr,
              &without.frame.labels, &confirmed);
  EXPECT_EQ(confirmed, without.cluster);
}

TEST(LabelMovers, KeypointsLabelledBeforeAreNoEvidence) {
  // The cluster already labelled (e.g. by a mover region): it confirms nothing, so its unmatched
  // neighbour stays static (a region must not spread through the check).
  const PinholeCamera camera;
  Scene s = MakeScene(camera);
  for (size_t i : s.cluster) s.frame.labels[i] = KeypointLabel::kGeometric;
  EXPECT_EQ(LabelMovers(camera, ScaleInfo::Geometric(1.2, 8), MoverCheckOptions(), s.frame,
                        s.points, nullptr, &s.frame.labels),
            0);
  EXPECT_EQ(s.frame.labels[s.unmatched], KeypointLabel::kStatic);
}

// A frame with the given keypoints (x, y, depth), every label static.
Frame FrameOf(const PinholeCamera& camera, int64_t index,
              const std::vector<std::array<float, 3>>& points) {
  std::vector<cv::KeyPoint> kps;
  std::vector<float> depth;
  for (const auto& p : points) {
    kps.emplace_back(p[0], p[1], 31.0f, 0.0f, 1.0f, 0);
    depth.push_back(p[2]);
  }
  Frame frame;
  frame.index = index;
  frame.features = BuildFrameFeatures(
      camera, kps, cv::Mat::zeros(static_cast<int>(kps.size()), 32, CV_8UC1), depth);
  frame.landmarks.assign(kps.size(), kNoLandmark);
  frame.labels.assign(kps.size(), KeypointLabel::kStatic);
  return frame;
}

TEST(MoverRegions, OneRegionPerClusterAtOneDepthWithEnoughKeypoints) {
  const PinholeCamera camera;  // no distortion: undistorted = detected pixels
  std::vector<std::array<float, 3>> pts;
  for (int k = 0; k < 12; ++k) pts.push_back({100.0f + 10 * k, 100.0f + (k % 2) * 8, 1.5f});  // A
  for (int k = 0; k < 12; ++k) pts.push_back({100.0f + 10 * k, 104.0f, 3.0f});  // B: behind A
  for (int k = 0; k < 9; ++k) pts.push_back({400.0f + 10 * k, 300.0f, 2.0f});  // C: too few
  pts.push_back({600.0f, 50.0f, 1.0f});  // not labelled
  Frame frame = FrameOf(camera, 4, pts);
  std::vector<KeypointLabel> labels(pts.size(), KeypointLabel::kGeometric);
  labels.back() = KeypointLabel::kStatic;
  MoverCheckOptions options;
  options.region_min_keypoints = 10;
  const std::vector<MoverRegion> regions = MoverRegionsOf(options, frame, labels);
  ASSERT_EQ(regions.size(), 2u);
  for (const MoverRegion& r : regions) {
    EXPECT_EQ(r.frame, 4);
    EXPECT_NEAR(r.min_u, 100.0, 1e-6);
    EXPECT_NEAR(r.max_u, 210.0, 1e-6);
    // Each cluster at one depth, widened by 10 %.
    EXPECT_NEAR(r.max_depth / r.min_depth, 1.1 / 0.9, 1e-9);
  }
  EXPECT_NEAR(regions[0].min_depth + regions[1].min_depth, 0.9 * 4.5, 1e-6);
  EXPECT_NEAR(std::min(regions[0].min_v, regions[1].min_v), 100.0, 1e-6);
  EXPECT_NEAR(std::max(regions[0].max_v, regions[1].max_v), 108.0, 1e-6);
  options.region_min_keypoints = 9;  // now C too
  EXPECT_EQ(MoverRegionsOf(options, frame, labels).size(), 3u);
}

TEST(MoverRegions, LabelInsideTheGrownBoxAtItsDepthForRegionFramesOnly) {
  const PinholeCamera camera;
  MoverRegion region;
  region.frame = 5;
  region.min_u = 100, region.max_u = 140, region.min_v = 100, region.max_v = 120;
  region.min_depth = 1.26, region.max_depth = 1.76;
  MoverCheckOptions options;
  options.radius_px = 30;
  options.region_growth_px = 10;
  options.region_frames = 4;
  // Two frames later the box is grown by 30 + 2 * 10 = 50 px: u in [50, 190], v in [50, 170].
  const std::vector<std::array<float, 3>> pts = {
      {60, 60, 1.5f},    // 0: inside, at its depth
      {185, 165, 1.3f},  // 1: inside, near its front
      {120, 110, 3.0f},  // 2: inside, behind it
      {200, 110, 1.5f},  // 3: beside the grown box
      {120, 110, 1.5f},  // 4: inside but already a mask label
      {120, 110, 1.1f},  // 5: inside, in front of it
  };
  Frame frame = FrameOf(camera, 7, pts);
  frame.labels[4] = KeypointLabel::kDynamicMask;
  EXPECT_EQ(LabelInMoverRegions({region}, options, frame, &frame.labels), 2);
  EXPECT_EQ(frame.labels[0], KeypointLabel::kGeometric);
  EXPECT_EQ(frame.labels[1], KeypointLabel::kGeometric);
  EXPECT_EQ(frame.labels[2], KeypointLabel::kStatic);
  EXPECT_EQ(frame.labels[3], KeypointLabel::kStatic);
  EXPECT_EQ(frame.labels[4], KeypointLabel::kDynamicMask);
  EXPECT_EQ(frame.labels[5], KeypointLabel::kStatic);
  // In its own frame and after region_frames it labels nothing.
  for (int64_t index : {5, 10}) {
    Frame other = FrameOf(camera, index, pts);
    EXPECT_EQ(LabelInMoverRegions({region}, options, other, &other.labels), 0) << index;
  }
  Frame last = FrameOf(camera, 9, {{60, 60, 1.5f}});  // 4 frames later: grown by 70 px
  EXPECT_EQ(LabelInMoverRegions({region}, options, last, &last.labels), 1);
}

}  // namespace
}  // namespace detslam
