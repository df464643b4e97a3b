#include "detslam/pipeline/stage_threads.h"

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <thread>

#if defined(__linux__)
#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

#include "detslam/pipeline/bounded_queue.h"

namespace detslam {
namespace {

TEST(StageThreads, AllStagesRunAndJoinReturns) {
  BoundedQueue<int> q(2);
  StageThreads stages([&] { q.Close(); });
  std::atomic<int> sum{0};
  stages.Start(
      "producer",
      [&] {
        for (int i = 1; i <= 100; ++i) q.Push(i);
      },
      [&] { q.Close(); });
  stages.RunHere("consumer", [&] {
    while (std::optional<int> v = q.Pop()) sum += *v;
  });
  stages.Join();
  EXPECT_EQ(sum.load(), 5050);
}

// A failing stage stops the others (which would otherwise block forever on their queues) and
// its exception reaches Join's caller instead of std::terminate.
TEST(StageThreads, AFailingStageEndsTheRunWithItsMessage) {
  BoundedQueue<int> a(1), b(1);
  StageThreads stages([&] {
    a.Close();
    b.Close();
  });
  stages.Start("endless producer", [&] {
    for (int i = 0;; ++i) {
      if (!a.Push(i)) return;  // closed by the failing stage
    }
  });
  stages.Start("failing", [&] {
    for (int k = 0; k < 10; ++k) a.Pop();
    throw std::runtime_error("disk full in stage two");
  });
  stages.RunHere("waiting consumer", [&] {
    while (b.Pop()) {
    }
  });
  try {
    stages.Join();
    FAIL() << "Join did not rethrow";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "disk full in stage two");
  }
}

TEST(StageThreads, TheFirstErrorWins) {
  StageThreads stages(nullptr);
  stages.RunHere("first", [] { throw std::runtime_error("first"); });
  stages.RunHere("second", [] { throw std::runtime_error("second"); });
  try {
    stages.Join();
    FAIL() << "Join did not rethrow";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "first");
  }
}

#if defined(__linux__)
// The nice value of the calling thread only (not the process's other threads), inherited by the
// threads it starts.
TEST(StageThreads, LowerThisThreadPriorityChangesTheCallingThreadOnly) {
  const auto nice_of_this_thread = [] {
    return getpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)));
  };
  const int before = nice_of_this_thread();
  int lowered = -100, child = -100;
  std::thread t([&] {
    ASSERT_TRUE(LowerThisThreadPriority(before + 3));
    lowered = nice_of_this_thread();
    std::thread grandchild([&] { child = nice_of_this_thread(); });
    grandchild.join();
  });
  t.join();
  EXPECT_EQ(lowered, before + 3);
  EXPECT_EQ(child, before + 3);
  EXPECT_EQ(nice_of_this_thread(), before);
}

// SCHED_IDLE for the calling thread only, inherited by the threads it starts.
TEST(StageThreads, MakeThisThreadIdlePriorityChangesTheCallingThreadOnly) {
  const auto policy_of_this_thread = [] {
    int policy = -1;
    sched_param param{};
    pthread_getschedparam(pthread_self(), &policy, &param);
    return policy;
  };
  const int before = policy_of_this_thread();
  ASSERT_NE(before, SCHED_IDLE);
  int idle = -1, child = -1;
  std::thread t([&] {
    ASSERT_TRUE(MakeThisThreadIdlePriority());
    idle = policy_of_this_thread();
    std::thread grandchild([&] { child = policy_of_this_thread(); });
    grandchild.join();
  });
  t.join();
  EXPECT_EQ(idle, SCHED_IDLE);
  EXPECT_EQ(child, SCHED_IDLE);
  EXPECT_EQ(policy_of_this_thread(), before);
}
#endif

}  // namespace
}  // namespace detslam
