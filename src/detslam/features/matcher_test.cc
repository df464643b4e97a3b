#include "detslam/features/matcher.h"

#include <gtest/gtest.h>

#include <vector>

#include "detslam/core/rng.h"
#include "detslam/features/orb_extractor.h"

namespace detslam {
namespace {

TEST(RotationConsistencyTest, KeepsThreeLargestBinsAboveTenPercent) {
  std::vector<float> diffs;
  for (int i = 0; i < 50; ++i) diffs.push_back(15.f);  // bin 1 (12 deg bins)
  for (int i = 0; i < 20; ++i) diffs.push_back(-5.f);  // wraps to 355: bin 29
  for (int i = 0; i < 6; ++i) diffs.push_back(100.f);  // bin 8: third, 12% of max: kept
  for (int i = 0; i < 3; ++i) diffs.push_back(200.f);  // bin 16: fourth: dropped
  const std::vector<bool> keep = RotationConsistency(diffs);
  ASSERT_EQ(keep.size(), diffs.size());
  for (size_t i = 0; i < diffs.size(); ++i) EXPECT_EQ(keep[i], i < 76) << i;
}

TEST(RotationConsistencyTest, DropsSmallSecondAndThirdBins) {
  std::vector<float> diffs(100, 181.f);
  diffs.push_back(10.f);                               // 1 < 10% of 100: dropped
  for (int i = 0; i < 9; ++i) diffs.push_back(725.f);  // 725 = 5 (mod 360): bin 0, 10 entries
  const std::vector<bool> keep = RotationConsistency(diffs);
  for (size_t i = 0; i < 100; ++i) EXPECT_TRUE(keep[i]);
  // Bin 0 has 10 entries = 10% of the max: kept (only "< 10%" is dropped).
  for (size_t i = 100; i < diffs.size(); ++i) EXPECT_TRUE(keep[i]) << i;
  diffs.pop_back();  // now 9 in bin 0: dropped
  const std::vector<bool> keep2 = RotationConsistency(diffs);
  for (size_t i = 100; i < diffs.size(); ++i) EXPECT_FALSE(keep2[i]) << i;
  EXPECT_TRUE(RotationConsistency({}).empty());
}

// Descriptor row with the first `bits` bits of `base` flipped.
cv::Mat Flipped(const cv::Mat& base, int first_bit, int bits) {
  cv::Mat out = base.clone();
  for (int b = first_bit; b < first_bit + bits; ++b) out.at<uint8_t>(0, b / 8) ^= 1u << (b % 8);
  return out;
}

TEST(MatchBruteForceTest, RatioDistanceAndOneToOne) {
  Rng rng(5);
  cv::Mat a0(1, 32, CV_8UC1), a1(1, 32, CV_8UC1), a2(1, 32, CV_8UC1);
  for (cv::Mat* m : {&a0, &a1, &a2}) {
    for (int i = 0; i < 32; ++i)
      m->at<uint8_t>(0, i) = static_cast<uint8_t>(rng.UniformInt(0, 255));
  }
  cv::Mat desc_a, desc_b;
  cv::vconcat(std::vector<cv::Mat>{a0, a1, a2, Flipped(a0, 0, 6)}, desc_a);
  // b0 is 5 bits from a0 (and 11 from a3); b1 is 30 bits from a1, b2 is 32 from a1 (ratio fails);
  // b3 is 60 bits from a2 (too far for distance 50).
  cv::vconcat(std::vector<cv::Mat>{Flipped(a0, 100, 5), Flipped(a1, 0, 30), Flipped(a1, 200, 32),
                                   Flipped(a2, 0, 60)},
              desc_b);
  ASSERT_EQ(DescriptorDistance(desc_a.ptr(3), desc_b.ptr(0)), 11);
  std::vector<cv::KeyPoint> kp_a(4, cv::KeyPoint(0, 0, 31, 10.f)),
      kp_b(4, cv::KeyPoint(0, 0, 31, 10.f));
  MatchOptions options;
  options.check_orientation = false;
  std::vector<cv::DMatch> m = MatchBruteForce(kp_a, desc_a, kp_b, desc_b, options);
  // a0 and a3 both pick b0; a0 (distance 5) wins. a1 fails the ratio (30 vs 0.7*32), a2 distance.
  ASSERT_EQ(m.size(), 1u);
  EXPECT_EQ(m[0].queryIdx, 0);
  EXPECT_EQ(m[0].trainIdx, 0);
  EXPECT_EQ(m[0].distance, 5.f);

  options.ratio = 0.95;            // a1 -> b1 now passes (30 < 0.95 * 32)
  options.max_distance = kThHigh;  // a2 -> b3 (60) now passes
  m = MatchBruteForce(kp_a, desc_a, kp_b, desc_b, options);
  ASSERT_EQ(m.size(), 3u);
  EXPECT_EQ(m[1].queryIdx, 1);
  EXPECT_EQ(m[1].trainIdx, 1);
  EXPECT_EQ(m[2].queryIdx, 2);
  EXPECT_EQ(m[2].trainIdx, 3);
  EXPECT_EQ(m[2].distance, 60.f);
}

TEST(MatchWithinGroupsTest, PairsOnlyWithinAGroup) {
  Rng rng(8);
  cv::Mat a0(1, 32, CV_8UC1), a1(1, 32, CV_8UC1);
  for (cv::Mat* m : {&a0, &a1}) {
    for (int i = 0; i < 32; ++i)
      m->at<uint8_t>(0, i) = static_cast<uint8_t>(rng.UniformInt(0, 255));
  }
  cv::Mat desc_a, desc_b;
  cv::vconcat(std::vector<cv::Mat>{a0, a1}, desc_a);
  // b0 near a1, b1 near a0, b2 far from both.
  cv::vconcat(std::vector<cv::Mat>{Flipped(a1, 0, 4), Flipped(a0, 0, 3), Flipped(a0, 0, 120)},
              desc_b);
  std::vector<cv::KeyPoint> kp_a(2, cv::KeyPoint(0, 0, 31, 10.f)),
      kp_b(3, cv::KeyPoint(0, 0, 31, 10.f));
  MatchOptions options;
  options.check_orientation = false;
  // Groups that keep each a away from its true partner: no match passes the distance test.
  EXPECT_TRUE(
      MatchWithinGroups(kp_a, desc_a, kp_b, desc_b, {{{0}, {0, 2}}, {{1}, {1}}}, options).empty());
  // Groups that pair them: the same matches as brute force.
  const std::vector<cv::DMatch> grouped =
      MatchWithinGroups(kp_a, desc_a, kp_b, desc_b, {{{0}, {1, 2}}, {{1}, {0}}}, options);
  const std::vector<cv::DMatch> brute = MatchBruteForce(kp_a, desc_a, kp_b, desc_b, options);
  ASSERT_EQ(grouped.size(), 2u);
  ASSERT_EQ(brute.size(), 2u);
  for (size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(grouped[k].queryIdx, brute[k].queryIdx);
    EXPECT_EQ(grouped[k].trainIdx, brute[k].trainIdx);
  }
  EXPECT_EQ(grouped[0].trainIdx, 1);
  EXPECT_EQ(grouped[1].trainIdx, 0);
}

TEST(MatchBruteForceTest, OrientationCheckRemovesInconsistentRotation) {
  Rng rng(6);
  const int n = 40;
  cv::Mat desc(n, 32, CV_8UC1);
  for (int r = 0; r < n; ++r) {
    for (int i = 0; i < 32; ++i)
      desc.at<uint8_t>(r, i) = static_cast<uint8_t>(rng.UniformInt(0, 255));
  }
  std::vector<cv::KeyPoint> kp_a, kp_b;
  for (int r = 0; r < n; ++r) {
    kp_a.emplace_back(cv::Point2f(r, r), 31.f, 100.f);
    // All rotate by about 30 deg, except match 7 which rotates by 190 deg.
    kp_b.emplace_back(cv::Point2f(r, r), 31.f, r == 7 ? 270.f : 70.f + (r % 3));
  }
  MatchOptions options;
  const std::vector<cv::DMatch> m = MatchBruteForce(kp_a, desc, kp_b, desc, options);
  ASSERT_EQ(m.size(), static_cast<size_t>(n - 1));
  for (const cv::DMatch& match : m) {
    EXPECT_NE(match.queryIdx, 7);
    EXPECT_EQ(match.queryIdx, match.trainIdx);
    EXPECT_EQ(match.distance, 0.f);
  }
  options.check_orientation = false;
  EXPECT_EQ(MatchBruteForce(kp_a, desc, kp_b, desc, options).size(), static_cast<size_t>(n));
}

}  // namespace
}  // namespace detslam
