// Where every pipeline thread starts. Each stage body runs in its own thread (or, with RunHere,
// in the calling thread) under the same rule: the first exception of any stage is kept, and
// `stop` is called so that the other stages end too (it closes every queue: a closed queue ends
// each stage's loop); Join() waits for all threads and rethrows that exception, so a failing
// stage ends the run with its message instead of calling std::terminate.
#pragma once

#include <exception>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace detslam {

// Lowers the calling thread's scheduling priority to `nice` (Linux: its nice value, 0..19; threads
// it starts later inherit it). Returns false where that is not possible (then nothing changes).
bool LowerThisThreadPriority(int nice);

// Puts the calling thread under Linux's SCHED_IDLE policy: it runs only on a core no other
// (normal-policy) thread of the machine wants, and a normal thread that wakes takes its core at
// once (with a nice value it would wait for the scheduler's granularity). Threads it starts later
// inherit it. Returns false where that is not possible (then nothing changes).
bool MakeThisThreadIdlePriority();

class StageThreads {
 public:
  explicit StageThreads(std::function<void()> stop);
  // Joins what is still running (after calling `stop`), without rethrowing.
  ~StageThreads();
  StageThreads(const StageThreads&) = delete;
  StageThreads& operator=(const StageThreads&) = delete;

  // Starts `body` in a new thread; `finished` (e.g. closing the stage's output queue) runs when
  // the body returns or throws.
  void Start(const std::string& name, std::function<void()> body,
             std::function<void()> finished = nullptr);
  // Runs `body` in the calling thread with the same error handling.
  void RunHere(const std::string& name, const std::function<void()>& body,
               const std::function<void()>& finished = nullptr);
  // Waits for every started thread; rethrows the first stage exception, if any.
  void Join();

 private:
  void Guarded(const std::string& name, const std::function<void()>& body,
               const std::function<void()>& finished);

  std::function<void()> stop_;
  std::vector<std::thread> threads_;
  std::mutex mutex_;
  std::exception_ptr first_error_;
};

}  // namespace detslam
