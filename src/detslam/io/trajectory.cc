#include "detslam/io/trajectory.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "detslam/core/atomic_file.h"
#include "detslam/core/check.h"
#include "detslam/io/text_lines.h"

namespace detslam {

Trajectory ReadTumTrajectory(const std::string& path) {
  Trajectory out;
  ForEachDataLine(path, [&](int line_no, const std::vector<std::string>& fields) {
    if (fields.size() < 8) {
      throw InputError(path, line_no,
                       "expected 8 fields 'timestamp tx ty tz qx qy qz qw', got " +
                           std::to_string(fields.size()));
    }
    StampedPose p;
    if (!ParseTimestamp(fields[0], &p.stamp)) {
      throw InputError(path, line_no, "malformed timestamp '" + fields[0] + "'");
    }
    double v[7];
    for (int k = 0; k < 7; ++k) v[k] = ParseDoubleField(path, line_no, fields[k + 1]);
    // Beyond 1000 km a value is no camera position, and its squares overflow the ATE alignment.
    constexpr double kMaxPositionM = 1e6;
    for (int k = 0; k < 3; ++k) {
      if (std::abs(v[k]) > kMaxPositionM)
        throw InputError(path, line_no, "position '" + fields[k + 1] + "' beyond 10^6 m");
    }
    const Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
    if (q.norm() < 1e-9) throw InputError(path, line_no, "zero quaternion");
    if (!std::isfinite(q.norm())) throw InputError(path, line_no, "quaternion too large");
    p.world_from_cam = Rigid3d(q, Eigen::Vector3d(v[0], v[1], v[2]));
    out.push_back(p);
  });
  return out;
}

std::string FormatTumLine(const StampedPose& pose) {
  const Eigen::Vector3d& t = pose.world_from_cam.translation();
  const Eigen::Quaterniond& q = pose.world_from_cam.rotation();
  char buf[256];
  std::snprintf(buf, sizeof(buf), "%s %.9f %.9f %.9f %.9f %.9f %.9f %.9f",
                pose.stamp.ToString().c_str(), t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
  return buf;
}

void WriteTumTrajectory(const std::string& path, const Trajectory& trajectory,
                        const std::string& header) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    std::istringstream hs(header);
    for (std::string line; std::getline(hs, line);) out << "# " << line << "\n";
    out << "# timestamp tx ty tz qx qy qz qw\n";
    for (const StampedPose& p : trajectory) out << FormatTumLine(p) << "\n";
  });
}

}  // namespace detslam
