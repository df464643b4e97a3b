// The 256 point pairs sampled by this project's rBRIEF descriptor.
//
// ORB uses a pattern learned on PASCAL images; this project instead generates its own, once,
// deterministically: a SplitMix64 generator with the fixed seed kOrbPatternSeed drives a
// Box-Muller transform, and each coordinate is drawn from an isotropic Gaussian with
// sigma = 31 / 5 (BRIEF's "G II" choice for a 31 x 31 patch), rounded to the nearest integer.
// Coordinates outside the patch ([-15, 15]) are redrawn (clipping by rejection, so the patch edge
// does not collect a pile of samples), and pairs whose two points coincide are redrawn. The
// generator and the transform are written out here (not std::normal_distribution), so the
// pattern is the same with every standard library.
#pragma once

#include <array>
#include <cstdint>

namespace detslam {

inline constexpr uint64_t kOrbPatternSeed = 0x0DE75A11ULL;
inline constexpr int kOrbPatternHalfSize = 15;  // coordinates lie in [-15, 15]

struct BriefPair {
  int8_t x1, y1, x2, y2;  // the test is I(x1, y1) < I(x2, y2), x to the right, y down
};

// The fixed pattern (generated on first use; thread-safe).
const std::array<BriefPair, 256>& OrbPattern();

}  // namespace detslam
