#include "detslam/pipeline/stage_threads.h"

#if defined(__linux__)
#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

#include <spdlog/spdlog.h>

namespace detslam {

bool LowerThisThreadPriority(int nice) {
#if defined(__linux__)
  const auto tid = static_cast<id_t>(syscall(SYS_gettid));
  return setpriority(PRIO_PROCESS, tid, nice) == 0;
#else
  (void)nice;
  return false;
#endif
}

bool MakeThisThreadIdlePriority() {
#if defined(__linux__)
  sched_param param{};
  param.sched_priority = 0;
  return pthread_setschedparam(pthread_self(), SCHED_IDLE, &param) == 0;
#else
  return false;
#endif
}

StageThreads::StageThreads(std::function<void()> stop) : stop_(std::move(stop)) {}

StageThreads::~StageThreads() {
  bool running = false;
  for (const std::thread& t : threads_) running = running || t.joinable();
  if (running && stop_) stop_();
  for (std::thread& t : threads_) {
    if (t.joinable()) t.join();
  }
}

void StageThreads::Guarded(const std::string& name, const std::function<void()>& body,
                           const std::function<void()>& finished) {
  try {
    body();
  } catch (...) {
    spdlog::debug("stage {} failed; stopping the other stages", name);
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      if (!first_error_) first_error_ = std::current_exception();
    }
    if (stop_) stop_();
  }
  if (finished) finished();
}

void StageThreads::Start(const std::string& name, std::function<void()> body,
                         std::function<void()> finished) {
  threads_.emplace_back([this, name, body = std::move(body), finished = std::move(finished)] {
    Guarded(name, body, finished);
  });
}

void StageThreads::RunHere(const std::string& name, const std::function<void()>& body,
                           const std::function<void()>& finished) {
  Guarded(name, body, finished);
}

void StageThreads::Join() {
  for (std::thread& t : threads_) {
    if (t.joinable()) t.join();
  }
  threads_.clear();
  std::exception_ptr error;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    error = first_error_;
  }
  if (error) std::rethrow_exception(error);
}

}  // namespace detslam
