// Running the built `detslam` command from tests: its output goes to a log file the test reads.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

namespace detslam::testing {

// Runs `binary args` through the shell with stdout and stderr into `log`; returns the exit status
// (-1 if it did not exit normally).
int RunCommand(const std::string& binary, const std::string& args,
               const std::filesystem::path& log);

// The whole file as bytes ("" if it cannot be read).
std::string ReadFileBytes(const std::filesystem::path& path);

// Removes `path` (file or folder) when the test process exits, if every test passed; otherwise it is
// kept and its path printed. DETSLAM_KEEP_TEST_OUTPUT=1 keeps everything.
void RemoveAtExit(const std::filesystem::path& path);

// A fresh, empty folder for one test, per process (two test runs on one machine never share it);
// removed at exit as RemoveAtExit says.
std::string TempDir(const std::string& name);

// A path for one file of a test in the temporary folder, per process (nothing is created; whatever
// the test writes there is removed at exit as RemoveAtExit says).
std::string TempPath(const std::string& name);

// A command started in the background (no shell), stdout and stderr into a log file, for tests
// that signal it while it runs. The destructor kills it if it still runs.
class ChildProcess {
 public:
  // Throws std::runtime_error if it cannot be started.
  ChildProcess(const std::string& binary, const std::vector<std::string>& args,
               const std::filesystem::path& log);
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  void Signal(int sig) const;
  // Waits until the log contains `text` or the process exits (false) or `timeout` passes (false).
  bool WaitForLog(const std::string& text, std::chrono::milliseconds timeout);
  // Waits for the exit: its status (128 + signal if a signal ended it), or -1 after `timeout`.
  int Wait(std::chrono::milliseconds timeout);

 private:
  bool Exited();  // reaps the process if it has exited (never blocks); true once it has
  pid_t pid_ = -1;
  int status_ = -1;  // once exited
  std::filesystem::path log_;
};

#ifdef DETSLAM_CLI_PATH
// The built `detslam` command (targets that define DETSLAM_CLI_PATH).
inline int RunCli(const std::string& args, const std::filesystem::path& log) {
  return RunCommand(DETSLAM_CLI_PATH, args, log);
}
#endif

}  // namespace detslam::testing
