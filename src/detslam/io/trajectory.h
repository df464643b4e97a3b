// Trajectories in the TUM format: one line per pose, `timestamp tx ty tz qx qy qz qw`, the pose
// being world_from_camera (camera position and orientation in the world). Lines starting with '#'
// and blank lines are skipped; fields may be separated by spaces, tabs or commas.
#pragma once

#include <string>
#include <vector>

#include "detslam/core/rigid3d.h"
#include "detslam/core/timestamp.h"

namespace detslam {

struct StampedPose {
  Timestamp stamp;
  Rigid3d world_from_cam;
};

using Trajectory = std::vector<StampedPose>;

// Reads a TUM trajectory. Throws InputError naming the file and line on a missing file, a line
// without 8 numbers, a non-finite value or a zero quaternion. Does not sort.
Trajectory ReadTumTrajectory(const std::string& path);

// Writes a TUM trajectory atomically (temporary file + rename), with `header` as '#' comment
// lines at the top. Stamps with 6 decimals, positions and quaternions with 9 significant decimals.
void WriteTumTrajectory(const std::string& path, const Trajectory& trajectory,
                        const std::string& header = "");

// Formats one pose as a TUM line (no newline).
std::string FormatTumLine(const StampedPose& pose);

}  // namespace detslam
