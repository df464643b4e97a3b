// Mathematical constants shared by the modules.
#pragma once

namespace detslam {

inline constexpr double kPi = 3.14159265358979323846;

}  // namespace detslam
