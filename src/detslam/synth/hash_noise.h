// Counter-based pseudo-random numbers for per-pixel sensor noise: a value depends only on
// (seed, frame, pixel, channel), never on the order in which threads visit pixels, so a frame is
// byte-identical however the rendering is split across threads.
#pragma once

#include <cmath>
#include <cstdint>

namespace detslam::synth {

// SplitMix64 finaliser: a bijective, well-mixing 64-bit hash.
inline uint64_t Mix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

inline uint64_t HashKey(uint64_t seed, uint64_t frame, uint64_t pixel, uint64_t channel) {
  return Mix64(Mix64(Mix64(seed ^ 0xD1B54A32D192ED03ULL) ^ frame) ^ (pixel * 8 + channel));
}

// Uniform in [0, 1).
inline double HashUniform(uint64_t key) {
  return static_cast<double>(Mix64(key) >> 11) * (1.0 / 9007199254740992.0);
}

// Standard normal by Box-Muller from two hashed uniforms.
inline double HashNormal(uint64_t key) {
  const double u1 = HashUniform(key ^ 0x1234567ULL) + 1e-300;
  const double u2 = HashUniform(key ^ 0x89ABCDEFULL);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
}

}  // namespace detslam::synth
