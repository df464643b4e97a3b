#include "detslam/mapping/map_bundle.h"

#include <gtest/gtest.h>

#include <atomic>
#include <memory>
#include <random>

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

// A window's bundle: the window optimised, the keyframes the caller holds and those outside it that
// see its landmarks most held fixed (as many as allowed), and no bundle when nothing anchors it.
TEST(BuildWindowBundle, FixesTheKeyFramesThatSeeTheWindowsPointsMost) {
  Map map(ScaleInfo::Geometric(1.2, 8));
  const KeyFrameId k0 = AddKeyFrameAt(&map, 0.0);  // the map's root
  const KeyFrameId k1 = AddKeyFrameAt(&map, 1.0);
  const KeyFrameId k2 = AddKeyFrameAt(&map, 2.0);
  const KeyFrameId k3 = AddKeyFrameAt(&map, 3.0);
  const LandmarkId a = map.AddLandmark(Eigen::Vector3d(1, 0, 2), k1);
  const LandmarkId b = map.AddLandmark(Eigen::Vector3d(2, 0, 2), k1);
  const LandmarkId only_outside = map.AddLandmark(Eigen::Vector3d(0, 0, 2), k0);
  for (KeyFrameId k : {k1, k2, k3}) {
    map.AddObservation(a, k, 0);
    map.AddObservation(b, k, 1);
  }
  map.AddObservation(b, k0, 0);             // k0 sees one of the window's points, k3 two
  map.AddObservation(only_outside, k0, 1);  // seen by no keyframe of the window
  auto poses = [](const MapBundle& m) {
    std::vector<std::pair<KeyFrameId, bool>> out;
    for (const BundleProblem::Pose& p : m.problem.poses) out.emplace_back(p.id, p.fixed);
    return out;
  };
  using Poses = std::vector<std::pair<KeyFrameId, bool>>;

  const MapBundle one = BuildWindowBundle(map, {k1, k2}, 1);
  EXPECT_EQ(poses(one), (Poses{{k1, false}, {k2, false}, {k3, true}}));
  ASSERT_EQ(one.problem.points.size(), 2u);  // a and b, not the point seen only outside
  EXPECT_EQ(one.problem.observations.size(), 6u);

  const MapBundle all = BuildWindowBundle(map, {k1, k2}, 5);
  EXPECT_EQ(poses(all), (Poses{{k1, false}, {k2, false}, {k3, true}, {k0, true}}));
  EXPECT_EQ(all.problem.observations.size(), 7u);  // b in k0 too

  // No keyframe fixed and no map root in the window: no gauge, no bundle.
  EXPECT_TRUE(BuildWindowBundle(map, {k1, k2}, 0).problem.poses.empty());
  // The map's root in the window anchors it.
  EXPECT_EQ(poses(BuildWindowBundle(map, {k0, k1}, 0)), (Poses{{k0, true}, {k1, false}}));
  // Keyframes held by the caller come first among the fixed ones and are not counted again.
  EXPECT_EQ(poses(BuildWindowBundle(map, {k1}, 0, {k2})), (Poses{{k1, false}, {k2, true}}));
  EXPECT_EQ(poses(BuildWindowBundle(map, {k1}, 1, {k2})),
            (Poses{{k1, false}, {k2, true}, {k3, true}}));
}

// Three keyframes that see the same 40 points; the landmarks are perturbed so that the bundle has
// something to do. Returns the store.
void FillNoisyMap(const PinholeCamera& camera, Map* map) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> lateral(-1.0, 1.0), depth(2.0, 3.0), noise(-0.05, 0.05);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 40; ++i) points.emplace_back(lateral(rng), 0.6 * lateral(rng), depth(rng));
  std::vector<KeyFrameId> kfs;
  for (int k = 0; k < 3; ++k) {
    KeyFrame kf;
    kf.cam_from_world = Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-0.2 * k, 0, 0));
    auto f = std::make_shared<FrameFeatures>();
    for (const Eigen::Vector3d& p : points) {
      const Eigen::Vector3d pc = kf.cam_from_world * p;
      const Eigen::Vector2d uv = camera.Project(pc);
      f->keypoints.emplace_back(static_cast<float>(uv.x()), static_cast<float>(uv.y()), 31.0f,
                                0.0f, 1.0f, 0);
      f->undist.push_back(uv);
      f->depth.push_back(static_cast<float>(pc.z()));
      f->u_right.push_back(static_cast<float>(uv.x() - camera.bf / pc.z()));
    }
    f->descriptors = cv::Mat(static_cast<int>(points.size()), 32, CV_8UC1, cv::Scalar(7));
    kf.features = f;
    kfs.push_back(map->AddKeyFrame(std::move(kf)));
  }
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d off(noise(rng), noise(rng), noise(rng));
    const LandmarkId lm = map->AddLandmark(points[i] + off, kfs[0]);
    for (KeyFrameId k : kfs) map->AddObservation(lm, k, i);
  }
  for (KeyFrameId k : kfs) map->UpdateConnections(k);
}

double MeanPointError(const Map& map, const PinholeCamera& camera) {
  double sum = 0;
  int n = 0;
  const KeyFrame& kf = map.keyframe(map.first_keyframe());
  for (size_t i = 0; i < kf.landmarks.size(); ++i) {
    const Eigen::Vector3d truth = camera.Unproject(kf.features->undist[i], kf.features->depth[i]);
    sum += (map.landmark(kf.landmarks[i]).position - truth).norm();
    ++n;
  }
  return sum / n;
}

TEST(GlobalBundleAdjustment, SolvesStopsOnRequestAndDiscardsAnOutgrownSolution) {
  const PinholeCamera camera;
  auto fresh = [&] {
    auto store = std::make_unique<MapStore>(ScaleInfo::Geometric(1.2, 8));
    FillNoisyMap(camera, &*store->Write());
    return store;
  };
  auto error = [&](MapStore& store) { return MeanPointError(*store.Read(), camera); };

  auto solved = fresh();
  const double before = error(*solved);
  ASSERT_GT(before, 0.02);
  int applied = 0;
  const BundleSummary full = GlobalBundleAdjustment(
      camera, 10, solved.get(), [&](Map&, const std::map<KeyFrameId, Rigid3d>&) { ++applied; });
  EXPECT_TRUE(full.usable);
  EXPECT_EQ(applied, 1);
  EXPECT_GT(full.iterations, 1);
  EXPECT_LT(error(*solved), 0.1 * before);

  // Asked to stop: at most one iteration, and what it did is kept.
  auto stopped = fresh();
  const std::atomic<bool> stop{true};
  const BundleSummary early =
      GlobalBundleAdjustment(camera, 10, stopped.get(), nullptr, nullptr, &stop);
  EXPECT_LE(early.iterations, 1);
  EXPECT_LT(early.iterations, full.iterations);

  // A solution the map has outgrown (still_valid false under the lock) changes nothing.
  auto outgrown = fresh();
  applied = 0;
  const BundleSummary discarded = GlobalBundleAdjustment(
      camera, 10, outgrown.get(), [&](Map&, const std::map<KeyFrameId, Rigid3d>&) { ++applied; },
      [](const Map&) { return false; });
  EXPECT_FALSE(discarded.usable);
  EXPECT_EQ(applied, 0);
  EXPECT_DOUBLE_EQ(error(*outgrown), before);
}

}  // namespace
}  // namespace detslam
