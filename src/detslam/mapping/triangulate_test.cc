// LocalMapper's triangulation of new landmarks (ORB-SLAM3's CreateNewMapPoints for RGB-D) on a
// hand-made two-keyframe map: far points without depth are triangulated where they should be;
// movers, close-depth keypoints, inconsistent matches and too-short baselines are not.
#include <gtest/gtest.h>

#include <cmath>

#include "detslam/core/rng.h"
#include "detslam/mapping/local_mapper.h"

namespace detslam {
namespace {

ScaleInfo TestScale() { return ScaleInfo::Geometric(1.2, 8); }

struct Scene {
  std::vector<Eigen::Vector3d> far_points;  // true positions of the keypoints 20..69
};

// Keyframes at x = 0 and x = `baseline` looking along +z. Keypoints per keyframe, same order:
// 0-19 anchors (close depth, shared landmarks that make the keyframes covisible), 20-69 far points
// at 6-8 m without depth, 70 a far point labelled a mover in the second keyframe, 71-75 far points
// whose second keypoint is 30 px off (an inconsistent match with an identical descriptor).
Scene Build(Map* map, double baseline, KeyFrameId* first, KeyFrameId* second) {
  const PinholeCamera camera;
  Rng rng(7);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 20; ++i)
    points.emplace_back(rng.Uniform(-0.5, 0.5), rng.Uniform(-0.3, 0.3), rng.Uniform(1.5, 2.5));
  for (int i = 20; i < 76; ++i)
    points.emplace_back(rng.Uniform(-2, 2), rng.Uniform(-1.2, 1.2), rng.Uniform(6, 8));
  cv::Mat descriptors(static_cast<int>(points.size()), 32, CV_8UC1);
  for (int r = 0; r < descriptors.rows; ++r) {
    for (int c = 0; c < 32; ++c)
      descriptors.at<uint8_t>(r, c) = static_cast<uint8_t>(rng.Uniform(0, 256));
  }
  Scene scene;
  scene.far_points.assign(points.begin() + 20, points.begin() + 70);
  KeyFrameId ids[2];
  for (int k = 0; k < 2; ++k) {
    KeyFrame kf;
    kf.cam_from_world =
        Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-baseline * k, 0, 0));
    auto f = std::make_shared<FrameFeatures>();
    for (size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector3d pc = kf.cam_from_world * points[i];
      Eigen::Vector2d uv = camera.Project(pc);
      if (k == 1 && i >= 71) uv.y() += 30.0;
      f->keypoints.emplace_back(static_cast<float>(uv.x()), static_cast<float>(uv.y()), 31.0f, 0.0f,
                                1.0f, 0);
      f->undist.push_back(uv);
      const bool close = i < 20;
      f->depth.push_back(close ? static_cast<float>(pc.z()) : -1.0f);
      f->u_right.push_back(close ? static_cast<float>(uv.x() - camera.bf / pc.z()) : -1.0f);
    }
    f->descriptors = descriptors.clone();
    kf.features = f;
    kf.labels.assign(points.size(), KeypointLabel::kStatic);
    if (k == 1) kf.labels[70] = KeypointLabel::kGeometric;
    ids[k] = map->AddKeyFrame(std::move(kf));
  }
  for (size_t i = 0; i < 20; ++i) {
    const LandmarkId lm = map->AddLandmark(points[i], ids[0]);
    map->AddObservation(lm, ids[0], i);
    map->AddObservation(lm, ids[1], i);
  }
  map->UpdateConnections(ids[1]);
  *first = ids[0];
  *second = ids[1];
  return scene;
}

LocalMapperOptions TriangulationOnly() {
  LocalMapperOptions o;
  o.local_ba = false;
  o.fuse = false;
  o.cull_keyframes = false;
  return o;
}

TEST(Triangulation, NewLandmarksForFarPointsWithoutDepth) {
  MapStore store(TestScale());
  KeyFrameId a, b;
  const Scene scene = Build(&*store.Write(), 0.3, &a, &b);
  LocalMapper mapper(PinholeCamera(), TriangulationOnly());
  const size_t before = store.Read()->NumLandmarks();
  const LocalMappingSummary summary = mapper.ProcessKeyFrame(b, &store);
  const MapStore::ReadAccess access = store.Read();
  const Map& map = *access;
  EXPECT_EQ(summary.triangulated, 50);
  EXPECT_EQ(map.NumLandmarks(), before + 50);
  const KeyFrame& kb = map.keyframe(b);
  for (size_t i = 20; i < 70; ++i) {
    ASSERT_NE(kb.landmarks[i], kNoLandmark) << i;
    const Landmark& lm = map.landmark(kb.landmarks[i]);
    EXPECT_LT((lm.position - scene.far_points[i - 20]).norm(), 1e-6) << i;
    EXPECT_EQ(lm.observations.size(), 2u);
    EXPECT_EQ(lm.observations.at(a), i);
  }
  EXPECT_EQ(kb.landmarks[70], kNoLandmark);                                       // the mover
  for (size_t i = 71; i < 76; ++i) EXPECT_EQ(kb.landmarks[i], kNoLandmark) << i;  // inconsistent
}

TEST(Triangulation, NothingWithTooShortABaselineOrWhenOff) {
  {
    MapStore store(TestScale());
    KeyFrameId a, b;
    Build(&*store.Write(), 0.05, &a, &b);  // below the sensor's 7.5 cm baseline
    LocalMapper mapper(PinholeCamera(), TriangulationOnly());
    EXPECT_EQ(mapper.ProcessKeyFrame(b, &store).triangulated, 0);
  }
  MapStore store(TestScale());
  KeyFrameId a, b;
  Build(&*store.Write(), 0.3, &a, &b);
  LocalMapperOptions off = TriangulationOnly();
  off.triangulate = false;
  LocalMapper mapper(PinholeCamera(), off);
  const size_t before = store.Read()->NumLandmarks();
  EXPECT_EQ(mapper.ProcessKeyFrame(b, &store).triangulated, 0);
  EXPECT_EQ(store.Read()->NumLandmarks(), before);
}

}  // namespace
}  // namespace detslam
