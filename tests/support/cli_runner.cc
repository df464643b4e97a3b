#include "support/cli_runner.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <mutex>
#include <stdexcept>
#include <thread>

#include <gtest/gtest.h>

extern char** environ;

namespace detslam::testing {

int RunCommand(const std::string& binary, const std::string& args,
               const std::filesystem::path& log) {
  const std::string cmd = binary + " " + args + " > '" + log.string() + "' 2>&1";
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string ReadFileBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

namespace {

std::mutex temp_mutex;
std::vector<std::filesystem::path>* temp_paths = nullptr;  // leaked on purpose: used at exit

// At exit: removes the test's temporary folders and files if every test passed, else keeps them
// for inspection and says where they are. DETSLAM_KEEP_TEST_OUTPUT=1 keeps them always.
void RemoveTempPaths() {
  std::lock_guard<std::mutex> lock(temp_mutex);
  const bool keep = std::getenv("DETSLAM_KEEP_TEST_OUTPUT") != nullptr ||
                    !::testing::UnitTest::GetInstance()->Passed();
  for (const std::filesystem::path& p : *temp_paths) {
    std::error_code ec;
    if (keep) {
      if (std::filesystem::exists(p, ec)) std::fprintf(stderr, "test output kept: %s\n", p.c_str());
    } else {
      std::filesystem::remove_all(p, ec);
    }
  }
}

}  // namespace

void RemoveAtExit(const std::filesystem::path& path) {
  std::lock_guard<std::mutex> lock(temp_mutex);
  if (temp_paths == nullptr) {
    temp_paths = new std::vector<std::filesystem::path>();
    std::atexit(RemoveTempPaths);
  }
  temp_paths->push_back(path);
}

std::string TempDir(const std::string& name) {
  namespace fs = std::filesystem;
  const fs::path p =
      fs::temp_directory_path() / ("detslam_it_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(p);
  fs::create_directories(p);
  RemoveAtExit(p);
  return p.string();
}

std::string TempPath(const std::string& name) {
  const std::filesystem::path p = std::filesystem::temp_directory_path() /
                                  ("detslam_" + std::to_string(::getpid()) + "_" + name);
  RemoveAtExit(p);
  return p.string();
}

ChildProcess::ChildProcess(const std::string& binary, const std::vector<std::string>& args,
                           const std::filesystem::path& log)
    : log_(log) {
  std::vector<std::string> argv_strings{binary};
  argv_strings.insert(argv_strings.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : argv_strings) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  const int err = posix_spawn(&pid_, binary.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (err != 0) throw std::runtime_error("cannot start " + binary);
}

ChildProcess::~ChildProcess() {
  if (pid_ > 0 && status_ < 0) {
    ::kill(pid_, SIGKILL);
    int status = 0;
    ::waitpid(pid_, &status, 0);
  }
}

void ChildProcess::Signal(int sig) const {
  if (pid_ > 0 && status_ < 0) ::kill(pid_, sig);
}

bool ChildProcess::Exited() {
  int status = 0;
  if (status_ < 0 && ::waitpid(pid_, &status, WNOHANG) == pid_)
    status_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return status_ >= 0;
}

bool ChildProcess::WaitForLog(const std::string& text, std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < end) {
    if (ReadFileBytes(log_).find(text) != std::string::npos) return true;
    if (Exited()) return ReadFileBytes(log_).find(text) != std::string::npos;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}

int ChildProcess::Wait(std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (!Exited()) {
    if (std::chrono::steady_clock::now() >= end) return -1;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return status_;
}

}  // namespace detslam::testing
