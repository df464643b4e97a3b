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

TEST(Timestamp, IntegerAndDifference) {
  Timestamp a, b;
  ASSERT_TRUE(ParseTimestamp("10", &a));
  ASSERT_TRUE(ParseTimestamp("10.02", &b));
  EXPECT_NEAR(AbsDiffSeconds(a, b), 0.02, 1e-12);
  EXPECT_TRUE(a < b);
}

}  // namespace
}  // namespace detslam
