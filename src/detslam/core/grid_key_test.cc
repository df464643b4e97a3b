#include "detslam/core/grid_key.h"

#include <gtest/gtest.h>

#include <set>

namespace detslam {
namespace {

TEST(GridKey, CellsRoundDownAlsoBelowZero) {
  EXPECT_EQ(GridCellOf(Eigen::Vector3d(0.05, -0.05, 0.25), 0.1), Eigen::Vector3i(0, -1, 2));
  EXPECT_EQ(GridCellOf(Eigen::Vector3f(-0.2f, 0.0f, 0.19f), 0.1f), Eigen::Vector3i(-2, 0, 1));
}

TEST(GridKey, NeighbouringAndFarCellsHaveDistinctKeys) {
  std::set<uint64_t> keys;
  int n = 0;
  for (int z = -1; z <= 1; ++z)
    for (int y = -1; y <= 1; ++y)
      for (int x = -1; x <= 1; ++x, ++n) keys.insert(GridCellKey(Eigen::Vector3i(x, y, z)));
  keys.insert(GridCellKey(Eigen::Vector3i((1 << 20) - 1, -(1 << 20), 0)));
  keys.insert(GridCellKey(Eigen::Vector3i(-(1 << 20), (1 << 20) - 1, 0)));
  EXPECT_EQ(keys.size(), static_cast<size_t>(n + 2));
}

}  // namespace
}  // namespace detslam
