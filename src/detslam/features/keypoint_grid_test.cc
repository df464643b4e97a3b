#include "detslam/features/keypoint_grid.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "detslam/core/rng.h"

namespace detslam {
namespace {

std::vector<size_t> BruteForce(const std::vector<Eigen::Vector2d>& positions,
                               const std::vector<int>& octaves, const ImageBounds& bounds, double x,
                               double y, double r, int min_level, int max_level) {
  std::vector<size_t> result;
  for (size_t i = 0; i < positions.size(); ++i) {
    const Eigen::Vector2d& p = positions[i];
    if (p.x() < bounds.min_x || p.x() >= bounds.max_x || p.y() < bounds.min_y ||
        p.y() >= bounds.max_y) {
      continue;
    }
    if (min_level >= 0 && octaves[i] < min_level) continue;
    if (max_level >= 0 && octaves[i] > max_level) continue;
    if (std::abs(p.x() - x) < r && std::abs(p.y() - y) < r) result.push_back(i);
  }
  return result;
}

TEST(KeypointGridTest, QueriesEqualBruteForce) {
  Rng rng(7);
  // Undistorted bounds are not the image rectangle in general: use an offset, non-integer box.
  const ImageBounds bounds{-12.5, 651.25, -8.75, 489.5};
  std::vector<Eigen::Vector2d> positions;
  std::vector<int> octaves;
  for (int i = 0; i < 3000; ++i) {
    positions.emplace_back(rng.Uniform(-30, 670), rng.Uniform(-30, 510));  // some outside
    octaves.push_back(rng.UniformInt(0, 7));
  }
  const KeypointGrid grid(positions, octaves, bounds);
  EXPECT_EQ(grid.size(), positions.size());
  size_t total_found = 0;
  for (int q = 0; q < 500; ++q) {
    const double x = rng.Uniform(-40, 680), y = rng.Uniform(-40, 520);
    const double r = rng.Uniform(0.5, 60);
    int min_level = rng.UniformInt(-1, 7);
    int max_level = rng.UniformInt(-1, 7);
    if (q % 3 == 0) min_level = max_level = -1;
    const std::vector<size_t> expected =
        BruteForce(positions, octaves, bounds, x, y, r, min_level, max_level);
    EXPECT_EQ(grid.FeaturesInArea(x, y, r, min_level, max_level), expected)
        << "query " << q << " at " << x << "," << y << " r " << r;
    total_found += expected.size();
  }
  EXPECT_GT(total_found, 5000u);  // the queries are not trivially empty
}

TEST(KeypointGridTest, HandMadeWindowIsSquareAndStrict) {
  const std::vector<Eigen::Vector2d> positions = {{100, 100}, {109.9, 100}, {110, 100},
                                                  {109, 109}, {90.5, 91},   {300, 300}};
  const std::vector<int> octaves = {0, 1, 0, 2, 3, 0};
  const KeypointGrid grid(positions, octaves, ImageBounds{});
  // |dx| < 10 and |dy| < 10: (110, 100) is exactly on the edge and excluded, the corner (109, 109)
  // is inside the square although outside the radius-10 circle.
  EXPECT_EQ(grid.FeaturesInArea(100, 100, 10), (std::vector<size_t>{0, 1, 3, 4}));
  EXPECT_EQ(grid.FeaturesInArea(100, 100, 10, 1), (std::vector<size_t>{1, 3, 4}));
  EXPECT_EQ(grid.FeaturesInArea(100, 100, 10, -1, 1), (std::vector<size_t>{0, 1}));
  EXPECT_EQ(grid.FeaturesInArea(100, 100, 10, 2, 2), (std::vector<size_t>{3}));
  EXPECT_TRUE(grid.FeaturesInArea(500, 50, 20).empty());
  EXPECT_TRUE(grid.FeaturesInArea(-100, -100, 50).empty());
}

}  // namespace
}  // namespace detslam
