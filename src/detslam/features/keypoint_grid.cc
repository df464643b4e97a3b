#include "detslam/features/keypoint_grid.h"

#include <algorithm>
#include <cmath>

#include "detslam/core/check.h"

namespace detslam {

KeypointGrid::KeypointGrid(const std::vector<Eigen::Vector2d>& positions,
                           const std::vector<int>& octaves, const ImageBounds& bounds)
    : positions_(positions), octaves_(octaves), bounds_(bounds), cells_(kCols * kRows) {
  DETSLAM_CHECK_MSG(positions.size() == octaves.size(),
                    "positions " << positions.size() << " vs octaves " << octaves.size());
  DETSLAM_CHECK(bounds.max_x > bounds.min_x && bounds.max_y > bounds.min_y);
  inv_cell_w_ = kCols / (bounds.max_x - bounds.min_x);
  inv_cell_h_ = kRows / (bounds.max_y - bounds.min_y);
  for (size_t i = 0; i < positions_.size(); ++i) {
    int col, row;
    if (CellOf(positions_[i].x(), positions_[i].y(), &col, &row)) {
      cells_[row * kCols + col].push_back(i);
    }
  }
}

bool KeypointGrid::CellOf(double x, double y, int* col, int* row) const {
  if (!(x >= bounds_.min_x && x < bounds_.max_x && y >= bounds_.min_y && y < bounds_.max_y)) {
    return false;
  }
  *col = std::min(kCols - 1, static_cast<int>((x - bounds_.min_x) * inv_cell_w_));
  *row = std::min(kRows - 1, static_cast<int>((y - bounds_.min_y) * inv_cell_h_));
  return true;
}

std::vector<size_t> KeypointGrid::FeaturesInArea(double x, double y, double radius, int min_level,
                                                 int max_level) const {
  std::vector<size_t> result;
  if (cells_.empty() || !(radius > 0)) return result;
  const int col0 = static_cast<int>(std::floor((x - radius - bounds_.min_x) * inv_cell_w_));
  const int col1 = static_cast<int>(std::floor((x + radius - bounds_.min_x) * inv_cell_w_));
  const int row0 = static_cast<int>(std::floor((y - radius - bounds_.min_y) * inv_cell_h_));
  const int row1 = static_cast<int>(std::floor((y + radius - bounds_.min_y) * inv_cell_h_));
  if (col1 < 0 || row1 < 0 || col0 >= kCols || row0 >= kRows) return result;
  for (int row = std::max(0, row0); row <= std::min(kRows - 1, row1); ++row) {
    for (int col = std::max(0, col0); col <= std::min(kCols - 1, col1); ++col) {
      for (size_t i : cells_[row * kCols + col]) {
        if (min_level >= 0 && octaves_[i] < min_level) continue;
        if (max_level >= 0 && octaves_[i] > max_level) continue;
        if (std::abs(positions_[i].x() - x) < radius && std::abs(positions_[i].y() - y) < radius) {
          result.push_back(i);
        }
      }
    }
  }
  std::sort(result.begin(), result.end());
  return result;
}

}  // namespace detslam
