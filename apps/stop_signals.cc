#include "stop_signals.h"

#include <unistd.h>

#include <cstring>
#include <thread>

namespace detslam::app {
namespace {

std::atomic<bool> g_stop{false};
volatile std::sig_atomic_t g_signal = 0;
const char* g_message = "";
size_t g_message_size = 0;

extern "C" void OnStopSignal(int sig) {
  if (g_signal != 0) _exit(128 + sig);
  g_signal = sig;
  g_stop = true;
  const ssize_t ignored = write(STDERR_FILENO, g_message, g_message_size);
  (void)ignored;
}

}  // namespace

std::atomic<bool>& StopFlag() { return g_stop; }
int StopSignal() { return static_cast<int>(g_signal); }

StopSignals::StopSignals(const char* message) {
  static_assert(std::atomic<bool>::is_always_lock_free, "set from a signal handler");
  g_message = message;
  g_message_size = std::strlen(message);
  struct sigaction sa;
  std::memset(&sa, 0, sizeof(sa));
  sa.sa_handler = OnStopSignal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, &old_int_);
  sigaction(SIGTERM, &sa, &old_term_);
}

StopSignals::~StopSignals() {
  sigaction(SIGINT, &old_int_, nullptr);
  sigaction(SIGTERM, &old_term_, nullptr);
}

void StopSignals::Wait() const {
  // A signal handler cannot notify a condition variable: look at the flag every 100 ms.
  while (!g_stop.load()) std::this_thread::sleep_for(std::chrono::milliseconds(100));
}

}  // namespace detslam::app
