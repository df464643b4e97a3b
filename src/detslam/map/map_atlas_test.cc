// The atlas side of the Map: roots of several maps, merging one map into another.
#include <gtest/gtest.h>

#include "detslam/core/check.h"
#include "detslam/map/map.h"
#include "detslam/map/map_test_util.h"

namespace detslam {
namespace {

using map_test::PartsOf;
using map_test::RestoreLike;
using map_test::RowFeatures;

// Three keyframes of map `map_id`, each pair sharing `shared` landmarks; returns their ids.
std::vector<KeyFrameId> AddChain(Map* map, int map_id, double x0, size_t shared) {
  std::vector<KeyFrameId> ids;
  for (int k = 0; k < 3; ++k) {
    KeyFrame kf;
    kf.map_id = map_id;
    kf.features = RowFeatures(2 * shared + 2, 7);
    kf.cam_from_world =
        Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.1 * k, Eigen::Vector3d::UnitY())),
                Eigen::Vector3d(-x0 - 0.2 * k, 0.05 * k, 0.0));
    ids.push_back(map->AddKeyFrame(std::move(kf)));
  }
  for (int k = 0; k + 1 < 3; ++k) {
    for (size_t i = 0; i < shared; ++i) {
      const LandmarkId lm = map->AddLandmark(
          Eigen::Vector3d(x0 + 0.1 * static_cast<double>(i), 0.1 * k, 2.0), ids[k]);
      map->AddObservation(lm, ids[k], static_cast<size_t>(k) * shared + i);
      map->AddObservation(lm, ids[k + 1], static_cast<size_t>(k) * shared + i);
      map->UpdateLandmarkGeometry(lm);
    }
  }
  for (KeyFrameId id : ids) map->UpdateConnections(id);
  return ids;
}

TEST(MapAtlas, EachMapHasARootThatIsNeverCulledNorParented) {
  Map map(ScaleInfo::Geometric(1.2, 8));
  EXPECT_EQ(map.NewMapId(), 0);
  const std::vector<KeyFrameId> a = AddChain(&map, 0, 0.0, 4);
  EXPECT_EQ(map.NewMapId(), 1);
  const std::vector<KeyFrameId> b = AddChain(&map, map.NewMapId(), 5.0, 4);
  ASSERT_EQ(map.map_roots().size(), 2u);
  EXPECT_EQ(map.map_roots().at(0), a[0]);
  EXPECT_EQ(map.map_roots().at(1), b[0]);
  EXPECT_TRUE(map.IsMapRoot(b[0]));
  EXPECT_FALSE(map.IsMapRoot(b[1]));
  // A root gets no parent although it has covisible keyframes, and is never erased.
  EXPECT_EQ(map.keyframe(b[0]).parent, kNoKeyFrame);
  EXPECT_FALSE(map.keyframe(b[0]).covisibility.empty());
  map.EraseKeyFrame(b[0]);
  EXPECT_TRUE(map.HasKeyFrame(b[0]));
  // Maps share nothing.
  for (KeyFrameId k : b) {
    for (const auto& [other, w] : map.keyframe(k).covisibility) EXPECT_EQ(map.MapOf(other), 1);
  }
  EXPECT_EQ(map.KeyFramesOfMap(1), b);
  EXPECT_EQ(map.NumKeyFramesOfMap(1), b.size());
  EXPECT_EQ(map.NumKeyFramesOfMap(0) + b.size(), map.NumKeyFrames());
  EXPECT_EQ(map.NumKeyFramesOfMap(7), 0u);
}

TEST(MapAtlas, MergeMovesTheMapRigidlyAndReRootsItsTreeAtTheSeam) {
  Map map(ScaleInfo::Geometric(1.2, 8));
  const std::vector<KeyFrameId> a = AddChain(&map, 0, 0.0, 4);
  const std::vector<KeyFrameId> b = AddChain(&map, 1, 5.0, 4);
  std::map<KeyFrameId, Rigid3d> pose_before;
  for (KeyFrameId k : b) pose_before[k] = map.keyframe(k).cam_from_world;
  std::map<LandmarkId, Eigen::Vector3d> b_points, a_points;
  for (const auto& [id, lm] : map.landmarks())
    (map.MapOf(lm.observations.begin()->first) == 1 ? b_points : a_points)[id] = lm.position;

  const Rigid3d into_from_from(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.2, 1.0, 0.1).normalized())),
      Eigen::Vector3d(1.0, -2.0, 0.5));
  const std::map<KeyFrameId, Rigid3d> before = map.MergeMapInto(1, 0, into_from_from, b[2], a[1]);

  EXPECT_EQ(before.size(), 3u);
  EXPECT_EQ(map.map_roots().size(), 1u);
  EXPECT_FALSE(map.IsMapRoot(b[0]));
  EXPECT_EQ(map.NewMapId(), 2);  // map ids are never reused
  for (KeyFrameId k : b) {
    EXPECT_EQ(map.MapOf(k), 0);
    EXPECT_TRUE(before.at(k).translation().isApprox(pose_before.at(k).translation()));
    // The camera sees every moved point where it saw it before.
    const Eigen::Vector3d p(0.3, -0.2, 2.5);
    EXPECT_TRUE((map.keyframe(k).cam_from_world * (into_from_from * p))
                    .isApprox(pose_before.at(k) * p, 1e-12));
  }
  for (const auto& [id, p] : b_points)
    EXPECT_TRUE(map.landmark(id).position.isApprox(into_from_from * p, 1e-12));
  for (const auto& [id, p] : a_points) EXPECT_EQ(map.landmark(id).position, p);  // unmoved

  // One tree rooted at a[0]: every keyframe reaches it, children mirror parents.
  EXPECT_EQ(map.keyframe(b[2]).parent, a[1]);
  EXPECT_TRUE(map.keyframe(a[1]).children.count(b[2]));
  for (const auto& [id, kf] : map.keyframes()) {
    KeyFrameId k = id;
    for (int guard = 0; map.keyframe(k).parent != kNoKeyFrame && guard < 10; ++guard)
      k = map.keyframe(k).parent;
    EXPECT_EQ(k, a[0]) << "keyframe " << id;
    if (kf.parent != kNoKeyFrame) {
      EXPECT_TRUE(map.keyframe(kf.parent).children.count(id));
    }
    for (KeyFrameId c : kf.children) EXPECT_EQ(map.keyframe(c).parent, id);
  }
}

TEST(MapAtlas, RestoreRefusesMapsThatShareAnything) {
  Map map(ScaleInfo::Geometric(1.2, 8));
  AddChain(&map, 0, 0.0, 4);
  AddChain(&map, 1, 5.0, 4);
  {
    auto [k, l] = PartsOf(map);
    const Map restored = RestoreLike(map, k, l);
    EXPECT_EQ(restored.map_roots(), map.map_roots());
    EXPECT_EQ(restored.NewMapId(), 2);
  }
  {
    auto [k, l] = PartsOf(map);
    k[4].map_id = 0;  // covisible with keyframes of map 1, parent in map 1
    EXPECT_THROW(RestoreLike(map, k, l), InputError);
  }
  {
    auto [k, l] = PartsOf(map);
    k[3].parent = 0;  // map 1's root hung below map 0
    EXPECT_THROW(RestoreLike(map, k, l), InputError);
  }
  {
    auto [k, l] = PartsOf(map);
    l[0].observations[3] = 9;  // a landmark of map 0 also seen from map 1 (a free slot)
    EXPECT_THROW(RestoreLike(map, k, l), InputError);
  }
}

}  // namespace
}  // namespace detslam
