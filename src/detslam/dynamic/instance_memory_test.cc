#include "detslam/dynamic/instance_memory.h"

#include <gtest/gtest.h>

namespace detslam {
namespace {

Instance Person(int x) {
  Instance i;
  i.class_name = "person";
  i.box = cv::Rect(x, 10, 50, 100);
  return i;
}

TEST(InstanceMemory, CarriesALostInstanceForAtMostMaxAgeFrames) {
  InstanceMemory memory(2);
  EXPECT_EQ(memory.Update({Person(0), Person(300)}).size(), 2u);
  // The person at x=300 is missed: it is carried for two frames, then dropped.
  std::vector<Instance> f1 = memory.Update({Person(2)});
  ASSERT_EQ(f1.size(), 2u);
  EXPECT_EQ(f1[1].box.x, 300);
  EXPECT_EQ(memory.Update({Person(4)}).size(), 2u);
  EXPECT_EQ(memory.Update({Person(6)}).size(), 1u);
}

TEST(InstanceMemory, OverlappingDetectionReplacesTheRememberedOne) {
  InstanceMemory memory(3);
  memory.Update({Person(100)});
  const std::vector<Instance> out = memory.Update({Person(105)});
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].box.x, 105);
}

TEST(InstanceMemory, ZeroAgeIsPassThrough) {
  InstanceMemory memory(0);
  memory.Update({Person(0)});
  EXPECT_TRUE(memory.Update({}).empty());
}

}  // namespace
}  // namespace detslam
