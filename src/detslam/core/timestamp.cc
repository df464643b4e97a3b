#include "detslam/core/timestamp.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace detslam {

std::string Timestamp::ToString() const {
  const int64_t us = (ns >= 0 ? ns + 500 : ns - 500) / 1000;
  const int64_t whole = us / 1000000;
  const int64_t frac = std::llabs(us % 1000000);
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%s%lld.%06lld", (us < 0 && whole == 0) ? "-" : "",
                static_cast<long long>(whole), static_cast<long long>(frac));
  return buf;
}

bool ParseTimestamp(const std::string& text, Timestamp* out) {
  size_t i = 0;
  bool negative = false;
  if (i < text.size() && (text[i] == '-' || text[i] == '+')) negative = text[i++] == '-';
  int64_t whole = 0;
  size_t digits = 0;
  // At most 9.2e9 s fit in int64 nanoseconds (year 2262): refuse more than 9e9 s.
  constexpr int64_t kMaxSeconds = 9000000000LL;
  while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]))) {
    whole = whole * 10 + (text[i++] - '0');
    if (whole > kMaxSeconds) return false;
    ++digits;
  }
  int64_t frac_ns = 0;
  if (i < text.size() && text[i] == '.') {
    ++i;
    int64_t scale = 100000000;
    while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]))) {
      frac_ns += (text[i++] - '0') * scale;
      scale /= 10;
      ++digits;
    }
  }
  if (digits == 0) return false;
  // Scientific notation (rare in TUM files) falls back to double parsing.
  if (i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (end == nullptr || *end != '\0' || !(std::abs(v) <= static_cast<double>(kMaxSeconds)))
      return false;
    *out = Timestamp::FromSeconds(v);
    return true;
  }
  if (i != text.size()) return false;
  const int64_t ns = whole * 1000000000LL + frac_ns;
  out->ns = negative ? -ns : ns;
  return true;
}

}  // namespace detslam
