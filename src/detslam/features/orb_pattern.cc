#include "detslam/features/orb_pattern.h"

#include <cmath>

namespace detslam {
namespace {

class SplitMix64 {
 public:
  explicit SplitMix64(uint64_t seed) : state_(seed) {}
  uint64_t Next() {
    uint64_t z = (state_ += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  }
  // Uniform in (0, 1): 53 random bits, never exactly 0.
  double Uniform() {
    return (static_cast<double>(Next() >> 11) + 0.5) * (1.0 / 9007199254740992.0);
  }

 private:
  uint64_t state_;
};

// One Gaussian coordinate (Box-Muller, cosine branch only), rounded and redrawn until in range.
int DrawCoordinate(SplitMix64* rng, double sigma) {
  constexpr double kTwoPi = 6.283185307179586;
  for (;;) {
    const double u1 = rng->Uniform();
    const double u2 = rng->Uniform();
    const double g = std::sqrt(-2.0 * std::log(u1)) * std::cos(kTwoPi * u2);
    const long v = std::lround(g * sigma);
    if (v >= -kOrbPatternHalfSize && v <= kOrbPatternHalfSize) return static_cast<int>(v);
  }
}

std::array<BriefPair, 256> GeneratePattern() {
  SplitMix64 rng(kOrbPatternSeed);
  const double sigma = (2 * kOrbPatternHalfSize + 1) / 5.0;
  std::array<BriefPair, 256> pattern{};
  for (BriefPair& pair : pattern) {
    int x1, y1, x2, y2;
    do {
      x1 = DrawCoordinate(&rng, sigma);
      y1 = DrawCoordinate(&rng, sigma);
      x2 = DrawCoordinate(&rng, sigma);
      y2 = DrawCoordinate(&rng, sigma);
    } while (x1 == x2 && y1 == y2);
    pair = {static_cast<int8_t>(x1), static_cast<int8_t>(y1), static_cast<int8_t>(x2),
            static_cast<int8_t>(y2)};
  }
  return pattern;
}

}  // namespace

const std::array<BriefPair, 256>& OrbPattern() {
  static const std::array<BriefPair, 256> pattern = GeneratePattern();
  return pattern;
}

}  // namespace detslam
