// Running the built `detslam` command from tests: its output goes to a log file the test reads.
#pragma once

#include <filesystem>
#include <string>

namespace detslam::testing {

// Runs `binary args` through the shell with stdout and stderr into `log`; returns the exit status
// (-1 if it did not exit normally).
int RunCommand(const std::string& binary, const std::string& args,
               const std::filesystem::path& log);

// The whole file as bytes ("" if it cannot be read).
std::string ReadFileBytes(const std::filesystem::path& path);

#ifdef DETSLAM_CLI_PATH
// The built `detslam` command (targets that define DETSLAM_CLI_PATH).
inline int RunCli(const std::string& args, const std::filesystem::path& log) {
  return RunCommand(DETSLAM_CLI_PATH, args, log);
}
#endif

}  // namespace detslam::testing
