#include "detslam/io/ply.h"

#include <cstring>
#include <ostream>

#include "detslam/core/atomic_file.h"
#include "detslam/core/check.h"

namespace detslam {
namespace {

// Appends a float in little-endian byte order whatever the host order is.
void AppendFloatLe(float f, std::string* out) {
  uint32_t bits = 0;
  std::memcpy(&bits, &f, sizeof(bits));
  for (int k = 0; k < 4; ++k) out->push_back(static_cast<char>((bits >> (8 * k)) & 0xFF));
}

}  // namespace

void WritePointCloudPly(const std::string& path, const std::vector<Eigen::Vector3d>& points,
                        const std::vector<Eigen::Matrix<uint8_t, 3, 1>>& colors) {
  if (!colors.empty() && colors.size() != points.size()) {
    throw InputError(path, 0,
                     "point cloud has " + std::to_string(points.size()) + " points but " +
                         std::to_string(colors.size()) + " colours");
  }
  const bool with_color = !colors.empty();
  std::string body;
  body.reserve(points.size() * (with_color ? 15 : 12));
  for (size_t i = 0; i < points.size(); ++i) {
    for (int k = 0; k < 3; ++k) AppendFloatLe(static_cast<float>(points[i][k]), &body);
    if (with_color) {
      for (int k = 0; k < 3; ++k) body.push_back(static_cast<char>(colors[i][k]));
    }
  }
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << "ply\nformat binary_little_endian 1.0\ncomment written by detslam\n";
    out << "element vertex " << points.size() << "\n";
    out << "property float x\nproperty float y\nproperty float z\n";
    if (with_color) out << "property uchar red\nproperty uchar green\nproperty uchar blue\n";
    out << "end_header\n";
    out.write(body.data(), static_cast<std::streamsize>(body.size()));
  });
}

}  // namespace detslam
