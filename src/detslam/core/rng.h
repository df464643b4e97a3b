// The one source of randomness: an explicitly seeded generator that is passed to whoever needs it.
// The same seed gives the same sequence on the same build (no global state, no time seeding).
#pragma once

#include <cstdint>
#include <random>

namespace detslam {

class Rng {
 public:
  explicit Rng(uint64_t seed) : engine_(seed) {}

  // Uniform integer in [lo, hi] (inclusive).
  int UniformInt(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(engine_); }
  // Uniform real in [lo, hi).
  double Uniform(double lo = 0.0, double hi = 1.0) {
    return std::uniform_real_distribution<double>(lo, hi)(engine_);
  }
  double Normal(double mean = 0.0, double stddev = 1.0) {
    return std::normal_distribution<double>(mean, stddev)(engine_);
  }
  uint64_t NextU64() { return engine_(); }
  // An independent child generator, e.g. one per frame, so that skipping work elsewhere does not
  // shift the random stream here.
  Rng Fork(uint64_t salt) { return Rng(engine_() ^ (salt * 0x9E3779B97F4A7C15ULL)); }

  std::mt19937_64& engine() { return engine_; }

 private:
  std::mt19937_64 engine_;
};

}  // namespace detslam
