// Ctrl-C (SIGINT) or SIGTERM while a command works: the first sets StopFlag() (a run then stops
// after the frame in progress and writes its outputs so far; run.json "interrupted": true; exit
// status 128 + signal); a second one exits at once (outputs being written atomically keep their
// previous contents).
#pragma once

#include <atomic>
#include <chrono>
#include <csignal>

namespace detslam::app {

// Set by the first SIGINT or SIGTERM while a StopSignals lives.
std::atomic<bool>& StopFlag();
// The signal that set it (0: none).
int StopSignal();

// Installs the handler for SIGINT and SIGTERM while it lives (the previous ones come back after).
class StopSignals {
 public:
  // `message`: what the first signal prints on stderr.
  explicit StopSignals(const char* message);
  ~StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  // Blocks until a signal sets StopFlag() (e.g. a viewer serving until Ctrl-C).
  void Wait() const;

 private:
  struct sigaction old_int_, old_term_;
};

}  // namespace detslam::app
