// Timestamps are integer nanoseconds inside the program; seconds as double only at file edges.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>

namespace detslam {

struct Timestamp {
  int64_t ns = 0;

  static Timestamp FromSeconds(double s) {
    return Timestamp{static_cast<int64_t>(std::llround(s * 1e9))};
  }
  double Seconds() const { return static_cast<double>(ns) * 1e-9; }
  // Fixed-point text with 6 decimals (TUM style), exact for microsecond stamps.
  std::string ToString() const;

  friend bool operator<(Timestamp a, Timestamp b) { return a.ns < b.ns; }
  friend bool operator<=(Timestamp a, Timestamp b) { return a.ns <= b.ns; }
  friend bool operator>(Timestamp a, Timestamp b) { return a.ns > b.ns; }
  friend bool operator==(Timestamp a, Timestamp b) { return a.ns == b.ns; }
  friend bool operator!=(Timestamp a, Timestamp b) { return a.ns != b.ns; }
};

// |a - b| in seconds.
inline double AbsDiffSeconds(Timestamp a, Timestamp b) {
  return std::abs(static_cast<double>(a.ns - b.ns)) * 1e-9;
}

// Parses a decimal seconds string exactly (no floating-point rounding of the integer part);
// returns false on malformed text.
bool ParseTimestamp(const std::string& text, Timestamp* out);

}  // namespace detslam
