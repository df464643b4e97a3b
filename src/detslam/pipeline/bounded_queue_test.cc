#include "detslam/pipeline/bounded_queue.h"

#include <gtest/gtest.h>

#include <thread>
#include <vector>

namespace detslam {
namespace {

TEST(BoundedQueue, PreservesOrderAcrossThreadsAndEndsOnClose) {
  BoundedQueue<int> q(3);
  std::thread producer([&] {
    for (int i = 0; i < 1000; ++i) ASSERT_TRUE(q.Push(i));
    q.Close();
  });
  std::vector<int> got;
  while (auto v = q.Pop()) got.push_back(*v);
  producer.join();
  ASSERT_EQ(got.size(), 1000u);
  for (int i = 0; i < 1000; ++i) EXPECT_EQ(got[static_cast<size_t>(i)], i);
}

TEST(BoundedQueue, PushAfterCloseFailsAndPopDrains) {
  BoundedQueue<int> q(2);
  EXPECT_TRUE(q.Push(1));
  q.Close();
  EXPECT_FALSE(q.Push(2));
  EXPECT_EQ(q.Pop(), std::optional<int>(1));
  EXPECT_EQ(q.Pop(), std::nullopt);
}

TEST(BoundedQueue, CloseWakesABlockedProducer) {
  BoundedQueue<int> q(1);
  ASSERT_TRUE(q.Push(0));
  bool result = true;
  std::thread producer([&] { result = q.Push(1); });  // blocks: queue full
  q.Close();
  producer.join();
  EXPECT_FALSE(result);
}

TEST(BoundedQueue, PushDroppingOldestNeverBlocksAndHandsBackTheOldest) {
  BoundedQueue<int> q(1);
  std::optional<int> dropped;
  ASSERT_TRUE(q.PushDroppingOldest(1, &dropped));
  EXPECT_EQ(dropped, std::nullopt);
  ASSERT_TRUE(q.PushDroppingOldest(2, &dropped));  // full: 1 makes room
  EXPECT_EQ(dropped, std::optional<int>(1));
  EXPECT_EQ(q.Pop(), std::optional<int>(2));
  ASSERT_TRUE(q.PushDroppingOldest(3, &dropped));
  EXPECT_EQ(dropped, std::nullopt);
  q.Close();
  EXPECT_FALSE(q.PushDroppingOldest(4, &dropped));
  EXPECT_EQ(q.Pop(), std::optional<int>(3));
  EXPECT_EQ(q.Pop(), std::nullopt);
}

}  // namespace
}  // namespace detslam
