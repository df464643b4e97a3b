// A 64 x 48 grid of keypoint indices over the image bounds, for square-window area queries (the
// projection searches of tracking and mapping, like ORB-SLAM's Frame::GetFeaturesInArea).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

namespace detslam {

struct ImageBounds {
  double min_x = 0, max_x = 640;  // x range of (undistorted) keypoints, pixels
  double min_y = 0, max_y = 480;  // y range of (undistorted) keypoints, pixels
};

class KeypointGrid {
 public:
  static constexpr int kCols = 64;
  static constexpr int kRows = 48;

  KeypointGrid() = default;
  // positions: undistorted keypoint positions; octaves: their pyramid levels (same size).
  // Keypoints outside the bounds are left out of the grid (never returned).
  KeypointGrid(const std::vector<Eigen::Vector2d>& positions, const std::vector<int>& octaves,
               const ImageBounds& bounds);

  // Indices (ascending) of keypoints with |px - x| < radius and |py - y| < radius, and octave in
  // [min_level, max_level]; a negative limit means no limit on that side.
  std::vector<size_t> FeaturesInArea(double x, double y, double radius, int min_level = -1,
                                     int max_level = -1) const;

  size_t size() const { return positions_.size(); }
  const ImageBounds& bounds() const { return bounds_; }

 private:
  // Cell holding (x, y); false if outside the bounds.
  bool CellOf(double x, double y, int* col, int* row) const;

  std::vector<Eigen::Vector2d> positions_;
  std::vector<int> octaves_;
  ImageBounds bounds_;
  double inv_cell_w_ = 0, inv_cell_h_ = 0;
  std::vector<std::vector<size_t>> cells_;  // row-major, kCols * kRows
};

}  // namespace detslam
