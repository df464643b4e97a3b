#include "support/shared_data.h"

#include <cstdlib>
#include <filesystem>

namespace detslam::testing {

std::string SharedRoot() {
  if (const char* env = std::getenv("DETSLAM_SHARED"); env != nullptr && *env != '\0') {
    return env;
  }
  return DETSLAM_SHARED_DIR_DEFAULT;
}

std::string SharedPath(const std::string& relative) {
  return (std::filesystem::path(SharedRoot()) / relative).string();
}

bool InCi() {
  const char* ci = std::getenv("CI");
  return ci != nullptr && std::string(ci) == "true";
}

bool PathExists(const std::string& path) { return std::filesystem::exists(path); }

}  // namespace detslam::testing
