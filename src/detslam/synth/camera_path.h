// Smooth camera trajectories of the presets (sums of sinusoids with seeded phases, or closed
// curves), as world_from_cam poses. Camera frame: x right, y down, z forward (optical axis).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>

#include "detslam/core/rigid3d.h"

namespace detslam::synth {

// Orientation of a camera at `position` looking at `target` with world +z up (world_from_cam).
Eigen::Matrix3d LookAtRotation(const Eigen::Vector3d& position, const Eigen::Vector3d& target);

// Orientation looking horizontally along heading `yaw` (radians, 0 = world +y, positive towards
// -x, i.e. counter-clockwise seen from above), tilted down by `pitch_down` and rolled by `roll`
// about the optical axis.
Eigen::Matrix3d YawPitchRollRotation(double yaw, double pitch_down, double roll);

// A closed elliptic circuit (semi-axes a along x, b along y, centred at (0, centre_y), 1.3 m high
// with a vertical bob of `bob` m) driven once per `period` seconds, looking `look_out_deg`
// outwards from the direction of travel. Periodic: the pose at t + period equals the pose at t.
Rigid3d EllipseCircuit(double t, double period, double a, double b, double centre_y, double bob,
                       double look_out_deg);

class CameraPath {
 public:
  // `preset` must be valid (see options.h); `seed` picks the phases of the motion.
  CameraPath(const std::string& preset, uint64_t seed);

  // Camera pose at time `t` seconds after the first frame.
  Rigid3d WorldFromCam(double t) const;

  // Period of the loop preset's circuit in seconds (the camera is back at its start then).
  static constexpr double kLoopPeriod = 32.0;
  // Period of the loop_long preset's circuit in seconds (a larger room and ellipse).
  static constexpr double kLoopLongPeriod = 64.0;
  // Duration of the lookalike preset's script (first part, passage, second part) in seconds;
  // beyond it the camera walks back to the first part (a true revisit).
  static constexpr double kLookalikeDuration = 45.0;

 private:
  std::string preset_;
  double phase_[8];
};

}  // namespace detslam::synth
