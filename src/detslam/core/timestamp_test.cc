#include "detslam/core/timestamp.h"

#include <gtest/gtest.h>

namespace detslam {
namespace {

TEST(Timestamp, ParsesTumStampExactly) {
  Timestamp t;
  ASSERT_TRUE(ParseTimestamp("1311868164.363181", &t));
  EXPECT_EQ(t.ns, 1311868164363181000LL);
  EXPECT_EQ(t.ToString(), "1311868164.363181");
}

TEST(Timestamp, RejectsMalformed) {
  Timestamp t;
  EXPECT_FALSE(ParseTimestamp("", &t));
  EXPECT_FALSE(ParseTimestamp("abc", &t));
  EXPECT_FALSE(ParseTimestamp("12.5x", &t));
  EXPECT_FALSE(ParseTimestamp(".", &t));
}

// Stamps beyond what int64 nanoseconds hold (found by the trajectory fuzz target: 90000000000
// overflowed) are refused, in plain and scientific notation.
TEST(Timestamp, RejectsStampsBeyondNineBillionSeconds) {
  Timestamp t;
  EXPECT_TRUE(ParseTimestamp("9000000000.5", &t));
  EXPECT_EQ(t.ns, 9000000000500000000LL);
  EXPECT_FALSE(ParseTimestamp("9000000001", &t));
  EXPECT_FALSE(ParseTimestamp("90000000000", &t));
  EXPECT_FALSE(ParseTimestamp("-99999999999999999999", &t));
  EXPECT_FALSE(ParseTimestamp("1e300", &t));
  EXPECT_FALSE(ParseTimestamp("-1e19", &t));
  EXPECT_TRUE(ParseTimestamp("1.305e9", &t));
  EXPECT_EQ(t.ns, 1305000000000000000LL);
}

TEST(Timestamp, IntegerAndDifference) {
  Timestamp a, b;
  ASSERT_TRUE(ParseTimestamp("10", &a));
  ASSERT_TRUE(ParseTimestamp("10.02", &b));
  EXPECT_NEAR(AbsDiffSeconds(a, b), 0.02, 1e-12);
  EXPECT_TRUE(a < b);
}

}  // namespace
}  // namespace detslam
