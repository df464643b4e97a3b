#include "detslam/core/check.h"

#include <spdlog/spdlog.h>

#include <cstdlib>

namespace detslam {

void CheckFailed(const char* file, int line, const char* condition, const std::string& message) {
  spdlog::critical("CHECK failed at {}:{}: {} {}", file, line, condition, message);
  std::abort();
}

}  // namespace detslam
