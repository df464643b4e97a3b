#include "detslam/geometry/alignment.h"

#include <gtest/gtest.h>

#include <cmath>

#include "detslam/core/rng.h"

namespace detslam {
namespace {

using V = Eigen::Vector3d;

// Rz(90 deg) maps (x, y, z) to (-y, x, z).
const Eigen::Matrix3d kRz90 =
    Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
const std::vector<V> kA = {V(0, 0, 0), V(1, 0, 0), V(0, 2, 0), V(0, 0, 3)};

TEST(AlignPointSets, RecoversHandMadeRigidMotion) {
  // b = Rz90 * a + (1, 2, 3), written out by hand.
  const std::vector<V> b = {V(1, 2, 3), V(1, 3, 3), V(-1, 2, 3), V(1, 2, 6)};
  const Alignment al = AlignPointSets(kA, b, /*with_scale=*/false);
  EXPECT_DOUBLE_EQ(al.scale, 1.0);
  EXPECT_NEAR((al.b_from_a.RotationMatrix() - kRz90).norm(), 0.0, 1e-12);
  EXPECT_NEAR((al.b_from_a.translation() - V(1, 2, 3)).norm(), 0.0, 1e-12);
  for (size_t i = 0; i < kA.size(); ++i) {
    EXPECT_NEAR((ApplyAlignment(al, kA[i]) - b[i]).norm(), 0.0, 1e-12) << i;
  }
}

TEST(AlignPointSets, RecoversHandMadeSimilarity) {
  // b = 2 * Rz90 * a + (1, 2, 3).
  const std::vector<V> b = {V(1, 2, 3), V(1, 4, 3), V(-3, 2, 3), V(1, 2, 9)};
  const Alignment sim = AlignPointSets(kA, b, /*with_scale=*/true);
  EXPECT_NEAR(sim.scale, 2.0, 1e-12);
  EXPECT_NEAR((sim.b_from_a.RotationMatrix() - kRz90).norm(), 0.0, 1e-12);
  EXPECT_NEAR((sim.b_from_a.translation() - V(1, 2, 3)).norm(), 0.0, 1e-12);

  // Without scale the rotation is unchanged and t = mean(b) - R mean(a):
  // mean(a) = (0.25, 0.5, 0.75), mean(b) = (0, 2.5, 4.5), R mean(a) = (-0.5, 0.25, 0.75).
  const Alignment rigid = AlignPointSets(kA, b, /*with_scale=*/false);
  EXPECT_DOUBLE_EQ(rigid.scale, 1.0);
  EXPECT_NEAR((rigid.b_from_a.RotationMatrix() - kRz90).norm(), 0.0, 1e-12);
  EXPECT_NEAR((rigid.b_from_a.translation() - V(0.5, 2.25, 3.75)).norm(), 0.0, 1e-12);
}

TEST(AlignPointSets, ReturnsRotationNotReflectionForMirroredPlanarSet) {
  // Mirror x -> -x of a planar set. The unconstrained optimum is a reflection; the proper
  // rotation by 180 deg about y fits the planar points exactly as well.
  const std::vector<V> a = {V(1, 0, 0), V(0, 1, 0), V(-2, 0, 0), V(0, -3, 0), V(1, 1, 0)};
  std::vector<V> b;
  for (const V& p : a) b.push_back(V(-p.x(), p.y(), p.z()));
  const Alignment al = AlignPointSets(a, b, false);
  const Eigen::Matrix3d r = al.b_from_a.RotationMatrix();
  EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
  EXPECT_NEAR((r * V(1, 0, 0) - V(-1, 0, 0)).norm(), 0.0, 1e-9);
  EXPECT_NEAR((r * V(0, 1, 0) - V(0, 1, 0)).norm(), 0.0, 1e-9);
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_NEAR((ApplyAlignment(al, a[i]) - b[i]).norm(), 0.0, 1e-9) << i;
  }
}

TEST(AlignPointSets, MirroredVolumeStillGivesProperRotation) {
  const std::vector<V> a = {V(0, 0, 0), V(1, 0, 0), V(0, 1, 0), V(0, 0, 1), V(1, 1, 1)};
  std::vector<V> b;
  for (const V& p : a) b.push_back(V(-p.x(), p.y(), p.z()));
  const Alignment al = AlignPointSets(a, b, true);
  EXPECT_NEAR(al.b_from_a.RotationMatrix().determinant(), 1.0, 1e-12);
  EXPECT_GT(al.scale, 0.0);
}

TEST(AlignPointSets, NoisySimilarityIsRecoveredClosely) {
  Rng rng(7);
  const Eigen::Matrix3d r = Eigen::AngleAxisd(0.7, V(1, -2, 0.5).normalized()).toRotationMatrix();
  const V t(-3, 0.5, 2);
  const double s = 0.8;
  std::vector<V> a, b;
  for (int i = 0; i < 200; ++i) {
    const V p(rng.Uniform(-5, 5), rng.Uniform(-5, 5), rng.Uniform(-1, 1));
    a.push_back(p);
    b.push_back(s * (r * p) + t + V(rng.Normal(0, 1e-3), rng.Normal(0, 1e-3), rng.Normal(0, 1e-3)));
  }
  const Alignment al = AlignPointSets(a, b, true);
  EXPECT_NEAR(al.scale, s, 1e-3);
  EXPECT_LT((al.b_from_a.RotationMatrix() - r).norm(), 1e-3);
  EXPECT_LT((al.b_from_a.translation() - t).norm(), 1e-3);
}

// The CHECK message goes to spdlog's stdout sink, so only the abort itself is matched here.
TEST(AlignPointSetsDeathTest, RejectsTooFewOrMismatchedPoints) {
  EXPECT_DEATH(AlignPointSets({V(0, 0, 0), V(1, 0, 0)}, {V(0, 0, 0), V(1, 0, 0)}, false), "");
  EXPECT_DEATH(AlignPointSets(kA, {V(0, 0, 0), V(1, 0, 0), V(0, 1, 0)}, false), "");
}

TEST(AlignPoseSets, RecoversAMotionFromPosesThatDoNotMove) {
  // Three poses at one position, turned about different axes: positions alone cannot fix the
  // rotation; orientations do.
  const Rigid3d b_from_a(Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())),
                         Eigen::Vector3d(0.5, -1.0, 2.0));
  std::vector<Rigid3d> a, b;
  for (const Eigen::Vector3d axis : {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ()}) {
    a.push_back(Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, axis)), Eigen::Vector3d(1, 1, 1)));
    b.push_back(b_from_a * a.back());
  }
  const Rigid3d found = AlignPoseSets(a, b);
  EXPECT_LT((found.RotationMatrix() - b_from_a.RotationMatrix()).norm(), 1e-12);
  EXPECT_LT((found.translation() - b_from_a.translation()).norm(), 1e-12);
  const Rigid3d one = AlignPoseSets({a[0]}, {b[0]});  // a single pose fixes it too
  EXPECT_LT((one.translation() - b_from_a.translation()).norm(), 1e-12);
}

}  // namespace
}  // namespace detslam
