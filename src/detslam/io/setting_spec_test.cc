#include "detslam/io/setting_spec.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace detslam {
namespace {
using ::testing::HasSubstr;

SettingSpec Spec(SettingType type, double min = -1e300, double max = 1e300) {
  SettingSpec s;
  s.key = "Test.Key";
  s.type = type;
  s.min = min;
  s.max = max;
  return s;
}

TEST(SettingSpecTest, ParsesEachTypeAndFormatsItBack) {
  SettingValue v;
  std::string why;
  ASSERT_TRUE(ParseSettingValue(Spec(SettingType::kBool), "Yes", &v, &why));
  EXPECT_EQ(std::get<bool>(v), true);
  ASSERT_TRUE(ParseSettingValue(Spec(SettingType::kInt), "640.0", &v, &why));
  EXPECT_EQ(std::get<int>(v), 640);
  ASSERT_TRUE(ParseSettingValue(Spec(SettingType::kDouble), "0.25", &v, &why));
  EXPECT_DOUBLE_EQ(std::get<double>(v), 0.25);
  EXPECT_EQ(FormatSettingValue(v), "0.25");
  ASSERT_TRUE(ParseSettingValue(Spec(SettingType::kString), "a b", &v, &why));
  EXPECT_EQ(std::get<std::string>(v), "a b");
  ASSERT_TRUE(
      ParseSettingValue(Spec(SettingType::kList), "person, chair,,traffic light ", &v, &why));
  EXPECT_EQ(std::get<std::vector<std::string>>(v),
            (std::vector<std::string>{"person", "chair", "traffic light"}));
  EXPECT_EQ(FormatSettingValue(v), "person,chair,traffic light");
  EXPECT_EQ(FormatSettingValue(SettingValue(false)), "false");
}

TEST(SettingSpecTest, RejectsWrongTypesAndOutOfRangeValues) {
  SettingValue v;
  std::string why;
  EXPECT_FALSE(ParseSettingValue(Spec(SettingType::kInt), "1.5", &v, &why));
  EXPECT_THAT(why, HasSubstr("must be an integer, got '1.5'"));
  EXPECT_FALSE(ParseSettingValue(Spec(SettingType::kDouble), "abc", &v, &why));
  EXPECT_THAT(why, HasSubstr("must be a finite number"));
  EXPECT_FALSE(ParseSettingValue(Spec(SettingType::kBool), "maybe", &v, &why));
  EXPECT_THAT(why, HasSubstr("must be a boolean"));
  const SettingSpec ranged = Spec(SettingType::kInt, 1, std::numeric_limits<double>::infinity());
  EXPECT_FALSE(ParseSettingValue(ranged, "0", &v, &why));
  EXPECT_THAT(why, HasSubstr("must be in [1, inf], got '0'"));
  EXPECT_TRUE(ParseSettingValue(ranged, "1", &v, &why));
  EXPECT_EQ(FormatSettingRange(ranged), "[1, inf]");
  EXPECT_EQ(FormatSettingRange(Spec(SettingType::kString)), "");
}

TEST(SettingSpecTest, ClosestKeyByEditDistance) {
  EXPECT_EQ(EditDistance("kitten", "sitting"), 3u);
  EXPECT_EQ(EditDistance("Alpha", "alpha"), 0u);
  std::vector<SettingSpec> known(3);
  known[0].key = "Dynamic.Alpha";
  known[1].key = "Dynamic.MaskDilation";
  known[2].key = "LoopClosing.Enabled";
  EXPECT_EQ(ClosestSettingKey("Dynamic.Alpah", known), "Dynamic.Alpha");
  EXPECT_EQ(ClosestSettingKey("LoopClosing.Enable", known), "LoopClosing.Enabled");
  EXPECT_EQ(ClosestSettingKey("x", {}), "");
}

}  // namespace
}  // namespace detslam
