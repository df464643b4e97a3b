#include "detslam/core/id_stamps.h"

#include <gtest/gtest.h>

#include <set>

#include "detslam/core/rng.h"

namespace detslam {
namespace {

TEST(IdStampsTest, InsertsOnceAndClearsInConstantTime) {
  IdStamps s;
  EXPECT_FALSE(s.Contains(0));
  EXPECT_FALSE(s.Contains(-1));
  EXPECT_FALSE(s.Contains(1000000));
  EXPECT_TRUE(s.Insert(5));
  EXPECT_FALSE(s.Insert(5));
  EXPECT_TRUE(s.Contains(5));
  EXPECT_FALSE(s.Contains(4));
  EXPECT_TRUE(s.Insert(0));
  EXPECT_TRUE(s.Insert(70000));  // grows
  EXPECT_TRUE(s.Contains(5));
  EXPECT_TRUE(s.Contains(70000));
  s.Clear();
  EXPECT_FALSE(s.Contains(5));
  EXPECT_FALSE(s.Contains(0));
  EXPECT_FALSE(s.Contains(70000));
  EXPECT_TRUE(s.Insert(70000));
}

TEST(IdStampsTest, AgreesWithStdSetOverManyRounds) {
  Rng rng(3);
  IdStamps s;
  for (int round = 0; round < 200; ++round) {
    s.Clear();
    std::set<int64_t> reference;
    for (int k = 0; k < 300; ++k) {
      const int64_t id = rng.UniformInt(0, 4999);
      EXPECT_EQ(s.Insert(id), reference.insert(id).second);
    }
    for (int64_t id = 0; id < 5000; id += 7) EXPECT_EQ(s.Contains(id), reference.count(id) > 0);
  }
}

}  // namespace
}  // namespace detslam
