// Test helpers for data that lives outside the repository, in ../shared (real TUM clips, models).
#pragma once

#include <string>

namespace detslam::testing {

// Root of the shared folder: $DETSLAM_SHARED if set, else the path configured at build time.
std::string SharedRoot();

// Absolute path of `relative` under the shared root (no existence check).
std::string SharedPath(const std::string& relative);

// True when running in CI (environment variable CI=true).
bool InCi();

}  // namespace detslam::testing

// Use at the top of a test that needs shared data. If the path is missing the test FAILS in CI
// (CI=true) and is SKIPPED elsewhere, with a message naming the path.
#define DETSLAM_REQUIRE_SHARED(relative_path)                                             \
  do {                                                                                     \
    const std::string detslam_shared_path_ = ::detslam::testing::SharedPath(relative_path); \
    if (!::detslam::testing::PathExists(detslam_shared_path_)) {                          \
      if (::detslam::testing::InCi()) {                                                    \
        FAIL() << "shared data missing (required in CI): " << detslam_shared_path_;        \
      } else {                                                                             \
        GTEST_SKIP() << "shared data missing: " << detslam_shared_path_;                   \
      }                                                                                    \
    }                                                                                      \
  } while (0)

namespace detslam::testing {
bool PathExists(const std::string& path);
}  // namespace detslam::testing
