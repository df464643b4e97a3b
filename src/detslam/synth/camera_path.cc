#include "detslam/synth/camera_path.h"

#include <algorithm>
#include <cmath>

#include "detslam/core/check.h"
#include "detslam/core/math.h"
#include "detslam/core/rng.h"
#include "detslam/synth/options.h"

namespace detslam::synth {
namespace {

constexpr double kDeg = kPi / 180.0;

// A sinusoid of amplitude `a` and period `period` seconds with phase `phase`.
double Wave(double t, double a, double period, double phase) {
  return a * std::sin(2.0 * kPi * t / period + phase);
}

}  // namespace

Rigid3d EllipseCircuit(double t, double period, double a, double b, double centre_y, double bob,
                       double look_out_deg) {
  // Starts at (0, centre_y - b) heading +x, counter-clockwise seen from above.
  const double th = 2.0 * kPi * t / period;
  const Eigen::Vector3d p(a * std::sin(th), centre_y - b * std::cos(th),
                          1.3 + bob * std::sin(3.0 * th));
  const Eigen::Vector2d tangent = Eigen::Vector2d(a * std::cos(th), b * std::sin(th)).normalized();
  const Eigen::Vector2d outward = Eigen::Vector2d(b * std::sin(th), -a * std::cos(th)).normalized();
  const Eigen::Vector2d look =
      std::cos(look_out_deg * kDeg) * tangent + std::sin(look_out_deg * kDeg) * outward;
  const double yaw = std::atan2(-look.x(), look.y());
  const Eigen::Matrix3d r = YawPitchRollRotation(yaw, 6 * kDeg + 2 * kDeg * std::sin(2 * th),
                                                 1.5 * kDeg * std::sin(5 * th));
  return Rigid3d(r, p);
}

Eigen::Matrix3d LookAtRotation(const Eigen::Vector3d& position, const Eigen::Vector3d& target) {
  const Eigen::Vector3d z = (target - position).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d r;
  r.col(0) = x;
  r.col(1) = y;
  r.col(2) = z;
  return r;
}

Eigen::Matrix3d YawPitchRollRotation(double yaw, double pitch_down, double roll) {
  Eigen::Matrix3d base;  // camera looking along world +y, image down = world -z
  base << 1, 0, 0, 0, 0, 1, 0, -1, 0;
  return Eigen::Matrix3d(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ())) * base *
         Eigen::Matrix3d(Eigen::AngleAxisd(-pitch_down, Eigen::Vector3d::UnitX())) *
         Eigen::Matrix3d(Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()));
}

CameraPath::CameraPath(const std::string& preset, uint64_t seed) : preset_(preset) {
  RequireSynthPreset(preset);
  Rng rng(seed ^ 0xCA3E7AULL);
  for (double& p : phase_) p = rng.Uniform(0.0, 2.0 * kPi);
}

Rigid3d CameraPath::WorldFromCam(double t) const {
  const double* ph = phase_;
  const Eigen::Vector3d base(0.0, -1.6, 1.3);
  if (preset_ == "static" || preset_ == "walking_xyz") {
    // About +-0.5 m along each axis, peak speed ~0.4 m/s, a few degrees of wobble.
    const Eigen::Vector3d p =
        base + Eigen::Vector3d(Wave(t, 0.42, 10.0, ph[0]) + Wave(t, 0.08, 3.7, ph[1]),
                               Wave(t, 0.30, 13.0, ph[2]) + Wave(t, 0.06, 4.3, ph[3]),
                               Wave(t, 0.28, 8.0, ph[4]) + Wave(t, 0.05, 2.9, ph[5]));
    const Eigen::Matrix3d r = YawPitchRollRotation(Wave(t, 4 * kDeg, 9.0, ph[6]),
                                                   8 * kDeg + Wave(t, 3 * kDeg, 7.0, ph[7]),
                                                   Wave(t, 2 * kDeg, 6.0, ph[1]));
    return Rigid3d(r, p);
  }
  if (preset_ == "walking_static" || preset_ == "sitting_static") {
    // A hand-held but nearly still camera: millimetres and fractions of a degree.
    const Eigen::Vector3d b =
        preset_ == "sitting_static" ? Eigen::Vector3d(0.0, -0.25, 1.25) : base;
    const Eigen::Vector3d p =
        b + Eigen::Vector3d(Wave(t, 0.008, 3.1, ph[0]) + Wave(t, 0.003, 0.9, ph[1]),
                            Wave(t, 0.006, 4.7, ph[2]), Wave(t, 0.007, 2.3, ph[3]));
    const Eigen::Matrix3d r = YawPitchRollRotation(Wave(t, 0.6 * kDeg, 5.3, ph[4]),
                                                   9 * kDeg + Wave(t, 0.4 * kDeg, 3.7, ph[5]),
                                                   Wave(t, 0.5 * kDeg, 6.1, ph[6]));
    return Rigid3d(r, p);
  }
  if (preset_ == "walking_rpy") {
    // Rotations about yaw +-25, pitch +-15, roll +-20 degrees (10-15 deg/s), little translation.
    const Eigen::Vector3d p =
        base + Eigen::Vector3d(Wave(t, 0.03, 5.0, ph[0]), Wave(t, 0.03, 6.0, ph[1]),
                               Wave(t, 0.03, 7.0, ph[2]));
    const Eigen::Matrix3d r = YawPitchRollRotation(Wave(t, 25 * kDeg, 11.0, ph[3]),
                                                   8 * kDeg + Wave(t, 15 * kDeg, 9.0, ph[4]),
                                                   Wave(t, 20 * kDeg, 13.0, ph[5]));
    return Rigid3d(r, p);
  }
  if (preset_ == "walking_halfsphere") {
    // On a half-sphere of 1 m diameter (behind its centre), always facing the table.
    const Eigen::Vector3d centre(0.0, -1.4, 1.3);
    const double az = Wave(t, 70 * kDeg, 16.0, ph[0]);
    const double el = Wave(t, 35 * kDeg, 11.0, ph[1]);
    const Eigen::Vector3d p =
        centre + 0.5 * Eigen::Vector3d(std::sin(az) * std::cos(el), -std::cos(az) * std::cos(el),
                                       std::sin(el));
    const Eigen::Vector3d target(Wave(t, 0.3, 7.0, ph[2]), 1.0, 0.95);
    return Rigid3d(LookAtRotation(p, target), p);
  }
  if (preset_ == "lookalike") {
    // Explores the first part of the room (x ~ -3.4), walks over to the second part (x ~ +3.4) and
    // explores it, always facing the far wall (+y, +-12 degrees): the first part is never seen
    // again. x follows -cos(pi s(u)) with s(u) = u - sin(2 pi u) / (2 pi), u = t / duration, so
    // the camera lingers at both ends (peak speed ~0.48 m/s mid-way); a side-to-side sway that
    // fades out during the passage.
    const double u = t / kLookalikeDuration;
    const double s = u - std::sin(2.0 * kPi * u) / (2.0 * kPi);
    const double fade = std::cos(kPi * u) * std::cos(kPi * u);
    const Eigen::Vector3d p(-3.4 * std::cos(kPi * s) + fade * Wave(t, 0.45, 9.0, ph[0]),
                            -0.6 + Wave(t, 0.25, 13.0, ph[1]), 1.3 + Wave(t, 0.1, 7.0, ph[2]));
    const Eigen::Matrix3d r = YawPitchRollRotation(Wave(t, 12 * kDeg, 10.0, ph[3]),
                                                   6 * kDeg + Wave(t, 3 * kDeg, 8.0, ph[4]),
                                                   Wave(t, 2 * kDeg, 6.0, ph[5]));
    return Rigid3d(r, p);
  }
  if (preset_ == "roam") {
    // Hand-held near (0, -1.0) in the office: faces the table and the far wall (yaw 0) for 7 s,
    // turns left over 7-11 s to face the back-left corner (yaw 135 deg: boxes, posters, the end
    // of the back shelf), roams there until 19 s, turns back over 19-25 s to face the front again
    // and stays there to the end. `--cover 8:2` hides the middle of the first turn: after it, the
    // camera sees only what it has never seen; it comes back to the start at ~24 s.
    auto smooth = [](double a, double b, double x) {
      const double s = std::clamp((x - a) / (b - a), 0.0, 1.0);
      return s * s * (3.0 - 2.0 * s);
    };
    const double yaw = 135 * kDeg * (smooth(7.0, 11.0, t) - smooth(19.0, 25.0, t)) +
                       Wave(t, 10 * kDeg, 9.0, ph[0]);
    const Eigen::Vector3d p(Wave(t, 0.35, 15.0, ph[1]), -1.0 + Wave(t, 0.15, 11.0, ph[2]),
                            1.3 + Wave(t, 0.08, 7.0, ph[3]));
    const Eigen::Matrix3d r = YawPitchRollRotation(yaw, 8 * kDeg + Wave(t, 3 * kDeg, 8.0, ph[4]),
                                                   Wave(t, 2 * kDeg, 6.0, ph[5]));
    return Rigid3d(r, p);
  }
  if (preset_ == "loop_long") {
    // An ellipse of 9.0 x 5.2 m in the large room, once per kLoopLongPeriod (~0.35 m/s, at most
    // 0.44 m/s), looking 55 degrees outwards (towards the furnished walls, 1.5-3 m away).
    return EllipseCircuit(t, kLoopLongPeriod, 4.5, 2.6, 0.0, 0.05, 55.0);
  }
  DETSLAM_CHECK_MSG(preset_ == "loop", "unhandled preset " << preset_);
  // An ellipse of 3.2 x 2.0 m in the free middle of the room, once per kLoopPeriod (~0.26 m/s),
  // looking 40 degrees outwards from the direction of travel (yaw rate ~11 deg/s).
  return EllipseCircuit(t, kLoopPeriod, 1.6, 1.0, -0.6, 0.04, 40.0);
}

}  // namespace detslam::synth
