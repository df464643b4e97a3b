// Cells of a regular 3-D grid (cubes of a given edge) and a 64-bit hash key per cell, for sparse
// voxel structures (the dense map's TSDF blocks, the dense benchmark's point grids).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>

namespace detslam {

// The cell holding `p` for cubes of edge `cell` (floor of each coordinate over the edge).
template <typename Scalar>
Eigen::Vector3i GridCellOf(const Eigen::Matrix<Scalar, 3, 1>& p, Scalar cell) {
  return Eigen::Vector3i(static_cast<int>(std::floor(p.x() / cell)),
                         static_cast<int>(std::floor(p.y() / cell)),
                         static_cast<int>(std::floor(p.z() / cell)));
}

// 21 bits per coordinate, offset to non-negative: distinct for every cell in [-2^20, 2^20) on each
// axis (a million cells either way, far beyond any room at centimetre cells).
inline uint64_t GridCellKey(const Eigen::Vector3i& c) {
  const auto part = [](int v) { return static_cast<uint64_t>(v + (1 << 20)) & 0x1FFFFF; };
  return part(c.x()) | (part(c.y()) << 21) | (part(c.z()) << 42);
}

}  // namespace detslam
