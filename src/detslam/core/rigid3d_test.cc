#include "detslam/core/rigid3d.h"

#include <gtest/gtest.h>

#include <cmath>

namespace detslam {
namespace {

TEST(Rigid3d, ComposeAndInverseCancel) {
  const Rigid3d b_from_a(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ())),
                         Eigen::Vector3d(1, 2, 3));
  const Rigid3d a_from_b = b_from_a.Inverse();
  const Rigid3d id = a_from_b * b_from_a;
  EXPECT_NEAR(id.translation().norm(), 0.0, 1e-12);
  EXPECT_NEAR(id.RotationAngle(), 0.0, 1e-7);
}

TEST(Rigid3d, TransformsPointHandMade) {
  // 90 degrees about z, then translate by (1, 0, 0): (1, 0, 0) -> (0, 1, 0) -> (1, 1, 0).
  const Rigid3d t(Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ())),
                  Eigen::Vector3d(1, 0, 0));
  const Eigen::Vector3d p = t * Eigen::Vector3d(1, 0, 0);
  EXPECT_NEAR(p.x(), 1.0, 1e-12);
  EXPECT_NEAR(p.y(), 1.0, 1e-12);
  EXPECT_NEAR(p.z(), 0.0, 1e-12);
}

TEST(Rigid3d, ExpLogRoundTrip) {
  Eigen::Matrix<double, 6, 1> xi;
  xi << 0.1, -0.2, 0.3, 0.4, -0.5, 0.6;
  const Rigid3d t = Rigid3d::Exp(xi);
  const Eigen::Matrix<double, 6, 1> back = t.Log();
  EXPECT_LT((back - xi).norm(), 1e-10);
  EXPECT_NEAR(t.RotationAngle(), xi.tail<3>().norm(), 1e-10);
}

TEST(Rigid3d, ExpOfPureTranslation) {
  Eigen::Matrix<double, 6, 1> xi;
  xi << 1, 2, 3, 0, 0, 0;
  const Rigid3d t = Rigid3d::Exp(xi);
  EXPECT_LT((t.translation() - Eigen::Vector3d(1, 2, 3)).norm(), 1e-12);
}

TEST(Rigid3d, HatIsCrossProduct) {
  const Eigen::Vector3d a(1, -2, 0.5), b(0.3, 4, -1);
  EXPECT_LT((Hat(a) * b - a.cross(b)).norm(), 1e-12);
}

}  // namespace
}  // namespace detslam
