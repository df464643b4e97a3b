// Point clouds as PLY (binary little-endian), e.g. the map's landmarks for viewing in MeshLab or
// CloudCompare.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

namespace detslam {

// Writes `points` as float x y z vertices, with uchar red green blue when `colors` is not empty
// (it must then have one entry per point, r g b order). Points are written as given (no
// filtering). The file is written atomically; throws InputError naming `path` on failure.
void WritePointCloudPly(const std::string& path, const std::vector<Eigen::Vector3d>& points,
                        const std::vector<Eigen::Matrix<uint8_t, 3, 1>>& colors);

}  // namespace detslam
