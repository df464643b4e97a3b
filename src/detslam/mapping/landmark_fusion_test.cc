// FuseLandmarksInto (ORB-SLAM's Fuse) on a hand-made two-keyframe map: landmarks of the first
// keyframe are projected into the second and matched there; a keypoint the tracker's geometric
// check labelled as a mover takes none.
#include <gtest/gtest.h>

#include "detslam/core/rng.h"
#include "detslam/mapping/landmark_fusion.h"

namespace detslam {
namespace {

// Keyframes at x = 0 and x = 0.1 m looking along +z, the same 40 points at 1.5-3 m seen by both
// (same keypoint order, depth known, one random descriptor per point); landmarks made from the
// first keyframe only. `mover`: the keypoint of the second keyframe labelled kGeometric (-1: none).
struct TwoKeyFrames {
  Map map{ScaleInfo::Geometric(1.2, 8)};
  KeyFrameId first = kNoKeyFrame, second = kNoKeyFrame;
  std::vector<LandmarkId> landmarks;
};

void Build(int mover, TwoKeyFrames* s) {
  const PinholeCamera camera;
  Rng rng(11);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 40; ++i)
    points.emplace_back(rng.Uniform(-0.8, 0.8), rng.Uniform(-0.6, 0.6), rng.Uniform(1.5, 3.0));
  cv::Mat descriptors(static_cast<int>(points.size()), 32, CV_8UC1);
  for (int r = 0; r < descriptors.rows; ++r) {
    for (int c = 0; c < 32; ++c)
      descriptors.at<uint8_t>(r, c) = static_cast<uint8_t>(rng.Uniform(0, 256));
  }
  KeyFrameId ids[2];
  for (int k = 0; k < 2; ++k) {
    KeyFrame kf;
    kf.cam_from_world = Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-0.1 * k, 0, 0));
    auto f = std::make_shared<FrameFeatures>();
    for (const Eigen::Vector3d& p : points) {
      const Eigen::Vector3d pc = kf.cam_from_world * p;
      const Eigen::Vector2d uv = camera.Project(pc);
      f->keypoints.emplace_back(static_cast<float>(uv.x()), static_cast<float>(uv.y()), 31.0f, 0.0f,
                                1.0f, 0);
      f->undist.push_back(uv);
      f->depth.push_back(static_cast<float>(pc.z()));
      f->u_right.push_back(static_cast<float>(uv.x() - camera.bf / pc.z()));
    }
    f->descriptors = descriptors.clone();
    f->grid = MakeKeypointGrid(camera, f->keypoints, f->undist);
    kf.features = f;
    kf.landmarks.assign(points.size(), kNoLandmark);
    kf.labels.assign(points.size(), KeypointLabel::kStatic);
    if (k == 1 && mover >= 0) kf.labels[static_cast<size_t>(mover)] = KeypointLabel::kGeometric;
    ids[k] = s->map.AddKeyFrame(std::move(kf));
  }
  for (size_t i = 0; i < points.size(); ++i) {
    const LandmarkId lm = s->map.AddLandmark(points[i], ids[0]);
    s->map.AddObservation(lm, ids[0], i);
    s->map.UpdateLandmarkGeometry(lm);
    s->map.UpdateLandmarkDescriptor(lm);
    s->landmarks.push_back(lm);
  }
  s->first = ids[0];
  s->second = ids[1];
}

int Fuse(TwoKeyFrames* s) {
  return FuseLandmarksInto(PinholeCamera(), s->map, s->second, s->landmarks,
                           s->map.keyframe(s->second).cam_from_world, ProjectionSearchOptions(),
                           FuseWinner::kMoreObserved);
}

TEST(LandmarkFusionTest, ProjectedLandmarksAreAddedToTheMatchingKeypoints) {
  TwoKeyFrames s;
  Build(-1, &s);
  EXPECT_EQ(Fuse(&s), 40);
  const KeyFrame& kf = s.map.keyframe(s.second);
  for (size_t i = 0; i < s.landmarks.size(); ++i) {
    EXPECT_EQ(kf.landmarks[i], s.landmarks[i]) << "keypoint " << i;
    EXPECT_EQ(s.map.landmark(s.landmarks[i]).observations.count(s.second), 1u);
  }
}

TEST(LandmarkFusionTest, AKeypointLabelledAMoverTakesNoLandmark) {
  TwoKeyFrames s;
  Build(7, &s);
  EXPECT_EQ(Fuse(&s), 39);
  const KeyFrame& kf = s.map.keyframe(s.second);
  EXPECT_EQ(kf.landmarks[7], kNoLandmark);
  EXPECT_EQ(s.map.landmark(s.landmarks[7]).observations.count(s.second), 0u);
  EXPECT_EQ(kf.landmarks[8], s.landmarks[8]);
}

}  // namespace
}  // namespace detslam
