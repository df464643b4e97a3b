// Helpers for the eval tests only (header-only, not part of the library API).
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <functional>

#include "detslam/io/trajectory.h"

namespace detslam::eval_test {

inline Timestamp Sec(double s) { return Timestamp::FromSeconds(s); }

// n poses at `rate_hz` starting at t0; pose(t) gives world_from_cam at time t (seconds from t0).
inline Trajectory MakeTrajectory(double t0, double rate_hz, int n,
                                 const std::function<Rigid3d(double)>& pose) {
  Trajectory out;
  for (int k = 0; k < n; ++k) {
    const double t = k / rate_hz;
    out.push_back({Timestamp{Sec(t0).ns + static_cast<int64_t>(std::llround(t * 1e9))}, pose(t)});
  }
  return out;
}

inline Rigid3d RotZ(double angle, const Eigen::Vector3d& t) {
  return Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ())), t);
}

// A smooth non-degenerate 3-D motion with changing orientation.
inline Rigid3d Wiggle(double t) {
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.3 * t, Eigen::Vector3d(0.2, 1, 0.1).normalized()));
  return Rigid3d(q, Eigen::Vector3d(std::sin(t), 0.5 * std::cos(0.7 * t), 0.2 * t));
}

}  // namespace detslam::eval_test
