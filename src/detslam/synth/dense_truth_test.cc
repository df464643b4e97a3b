#include "detslam/synth/dense_truth.h"

#include <gtest/gtest.h>

namespace detslam {
namespace {

synth::Scene ShellWithDesk() {
  synth::Scene scene;
  synth::SceneBox shell;
  shell.lo = Eigen::Vector3f(-2, -1, 0);
  shell.hi = Eigen::Vector3f(2, 3, 2.5);
  shell.interior = true;
  synth::SceneBox desk;
  desk.lo = Eigen::Vector3f(0, 1, 0);
  desk.hi = Eigen::Vector3f(1, 2, 0.75);
  scene.boxes = {shell, desk};
  return scene;
}

TEST(DenseTruth, SceneSurfaceDistanceInsideTheRoomAndAroundFurniture) {
  const synth::Scene scene = ShellWithDesk();
  EXPECT_NEAR(SceneSurfaceDistance(scene, {-1.5, 0.5, 1.2}), 0.5, 1e-9);   // 0.5 from x = -2
  EXPECT_NEAR(SceneSurfaceDistance(scene, {0.5, 1.5, 0.85}), 0.1, 1e-6);   // above the desk top
  EXPECT_NEAR(SceneSurfaceDistance(scene, {0.5, 1.5, 0.70}), 0.05, 1e-6);  // inside the desk
  EXPECT_NEAR(SceneSurfaceDistance(scene, {1.3, 2.4, 0.75}), 0.5, 1e-6);   // past a desk corner
  EXPECT_NEAR(SceneSurfaceDistance(scene, {-1.0, 0.0, 0.02}), 0.02, 1e-6); // on the floor
}

TEST(DenseTruth, PointGridFindsPointsWithinTheRadiusAcrossCells) {
  PointGrid grid(0.1);
  grid.Add({0.095, 0.0, 0.0});
  EXPECT_EQ(grid.size(), 1u);
  EXPECT_TRUE(grid.AnyWithin({0.105, 0.0, 0.0}, 0.1));   // the next cell
  EXPECT_TRUE(grid.AnyWithin({0.0, 0.0, 0.0}, 0.1));
  EXPECT_FALSE(grid.AnyWithin({0.0, 0.0, 0.0}, 0.09));
  EXPECT_FALSE(grid.AnyWithin({0.3, 0.0, 0.0}, 0.1));
  EXPECT_TRUE(grid.AnyWithin({0.095, -0.05, 0.05}, 0.1));
}

// The truth scores its own samples: the static surfaces rendered in the keyframes lie on the
// scene and cover it; the people's surfaces are "on people" and off the scene.
TEST(DenseTruth, ScoresRenderedStaticAndPeopleSurfaces) {
  SynthOptions so;
  so.preset = "walking_static";
  so.seed = 3;
  so.frames = 6;
  so.sensor_noise = false;
  const SyntheticSequence seq(so);
  std::vector<Eigen::Vector3d> statics, people;
  const PinholeCamera& cam = seq.camera();
  for (const int k : {0, 5}) {
    const SynthFrame f = seq.Render(k);
    for (int v = 0; v < cam.height; ++v) {
      for (int u = 0; u < cam.width; ++u) {
        const float z = f.true_depth.at<float>(v, u);
        if (!(z > 0.3f && z < 4.0f)) continue;
        const Eigen::Vector3d p = f.world_from_cam * cam.Unproject(Eigen::Vector2d(u, v), z);
        (f.instance_mask.at<uint16_t>(v, u) ? people : statics).push_back(p);
      }
    }
  }
  ASSERT_GT(people.size(), 500u) << "people in view";
  const DenseTruth truth(seq, {0, 5}, DenseTruthOptions());
  const DenseMapScore s = truth.Score(statics);
  EXPECT_EQ(s.points, statics.size());
  EXPECT_LT(s.static_median_m, 1e-3);
  EXPECT_EQ(s.near_person_off_scene, 0u);
  EXPECT_GT(s.completeness, 0.99);  // every pixel of the keyframes the truth sampled
  const DenseMapScore p = truth.Score(people);
  EXPECT_EQ(p.near_person, people.size());
  EXPECT_GT(p.SmearFraction(), 0.5);  // the feet touch the floor; the body stands off the scene
  const DenseMapScore none = truth.Score({});
  EXPECT_EQ(none.points, 0u);
  EXPECT_EQ(none.completeness, 0.0);
}

}  // namespace
}  // namespace detslam
