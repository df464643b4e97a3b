#include "detslam/core/association.h"

#include <gtest/gtest.h>

namespace detslam {
namespace {

using Pair = std::pair<size_t, size_t>;

std::vector<Timestamp> Stamps(std::initializer_list<double> s) {
  std::vector<Timestamp> out;
  for (double v : s) out.push_back(Timestamp::FromSeconds(v));
  return out;
}

TEST(Association, GreedyClosestFirstOneToOne) {
  // b[0] = 1.012 is closest to a[1] = 1.010 (0.002) and also within range of a[0] = 1.000 (0.012).
  // Greedy closest-first gives it to a[1]; a[0] then has nothing left within 0.02 s.
  const auto a = Stamps({1.000, 1.010});
  const auto b = Stamps({1.012});
  const auto m = AssociateTimestamps(a, b, {});
  ASSERT_EQ(m.size(), 1u);
  EXPECT_EQ(m[0], Pair(1, 0));
}

TEST(Association, MaxDifferenceIsExclusive) {
  const auto a = Stamps({1.0, 2.0});
  const auto b = Stamps({1.03, 2.019});
  const auto m = AssociateTimestamps(a, b, {});
  ASSERT_EQ(m.size(), 1u);
  EXPECT_EQ(m[0].first, 1u);
}

TEST(Association, OffsetShiftsSecondList) {
  const auto a = Stamps({1.0, 2.0});
  const auto b = Stamps({0.5, 1.5});
  AssociationOptions opt;
  opt.offset_s = 0.5;
  const auto m = AssociateTimestamps(a, b, opt);
  ASSERT_EQ(m.size(), 2u);
  EXPECT_EQ(m[0], Pair(0, 0));
  EXPECT_EQ(m[1], Pair(1, 1));
}

TEST(Association, EmptyAndUnsortedInputs) {
  EXPECT_TRUE(AssociateTimestamps({}, Stamps({1.0}), {}).empty());
  const auto a = Stamps({3.0, 1.0, 2.0});
  const auto b = Stamps({2.001, 3.001, 1.001});
  const auto m = AssociateTimestamps(a, b, {});
  ASSERT_EQ(m.size(), 3u);
  EXPECT_EQ(m[0], Pair(0, 1));
  EXPECT_EQ(m[1], Pair(1, 2));
  EXPECT_EQ(m[2], Pair(2, 0));
}

}  // namespace
}  // namespace detslam
