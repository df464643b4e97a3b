// Point clouds as PLY (binary little-endian), e.g. the map's landmarks for viewing in MeshLab or
// CloudCompare.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

namespace detslam {

// Writes `points` as float x y z vertices, with uchar red green blue when `colors` is not empty
// (it must then have one entry per point, r g b order), and float nx ny nz when `normals` is not
// empty (one per point). Points are written as given (no filtering). The file is written
// atomically; throws InputError naming `path` on failure.
void WritePointCloudPly(const std::string& path, const std::vector<Eigen::Vector3d>& points,
                        const std::vector<Eigen::Matrix<uint8_t, 3, 1>>& colors,
                        const std::vector<Eigen::Vector3d>& normals = {});

struct PointCloud {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Matrix<uint8_t, 3, 1>> colors;  // empty or one per point
  std::vector<Eigen::Vector3d> normals;              // empty or one per point
};

// Reads a binary little-endian PLY point cloud with one element, vertex, whose properties are
// float, double or uchar (x y z required; nx ny nz and red green blue read when present, others
// skipped), e.g. WritePointCloudPly's files. Throws InputError naming the file (and the header
// line) for anything else or a file shorter than its header says.
PointCloud ReadPointCloudPly(const std::string& path);

}  // namespace detslam
