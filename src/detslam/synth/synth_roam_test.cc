// The roam preset and the covered lens (--cover START:SECONDS): the sequence of the several-maps
// benchmark (a stretch the camera cannot see through, then only unseen ground, then the start).
#include <gtest/gtest.h>

#include <cmath>

#include "detslam/core/check.h"
#include "detslam/synth/sequence.h"
#include "detslam/synth/synth_test_util.h"

namespace detslam {
namespace {

using synth_test::Opts;

using synth_test::CheckError;

std::string CoverErrorOf(const std::string& text, SynthOptions* o) {
  try {
    ParseSynthCover(text, o);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(SynthRoamTest, CoverParsesAndBadCoversNameTheOption) {
  SynthOptions o = Opts("roam");
  EXPECT_EQ(CoverErrorOf("8:2", &o), "");
  EXPECT_DOUBLE_EQ(o.cover_start_s, 8.0);
  EXPECT_DOUBLE_EQ(o.cover_seconds, 2.0);
  EXPECT_EQ(CheckError(o), "");
  EXPECT_FALSE(o.Covered(239));  // 7.967 s
  EXPECT_TRUE(o.Covered(240));   // 8.000 s
  EXPECT_TRUE(o.Covered(299));
  EXPECT_FALSE(o.Covered(300));  // 10.000 s
  for (const std::string bad :
       {"", "8", "8:", ":2", "8:0", "a:2", "8:b", "-1:2", "1:2:3", "8:nan", "8:inf", "8:2x"}) {
    SynthOptions b = Opts("roam");
    const std::string error = CoverErrorOf(bad, &b);
    EXPECT_NE(error.find("--cover"), std::string::npos) << "'" << bad << "': " << error;
  }
  // Inside the sequence (30 s): after the first frame, ending before the last.
  for (const std::string outside : {"0:2", "29:1", "25:10"}) {
    SynthOptions b = Opts("roam");
    ParseSynthCover(outside, &b);
    EXPECT_NE(CheckError(b).find("--cover"), std::string::npos) << outside;
  }
}

TEST(SynthRoamTest, CoveredFramesAreBlackWithoutDepthWhileTheCameraMoves) {
  SynthOptions o = Opts("roam", 3), covered = o;
  covered.cover_start_s = 8.0;
  covered.cover_seconds = 2.0;
  const SyntheticSequence plain(o), seq(covered);
  for (int k : {239, 240, 270, 299, 300}) {
    const SynthFrame f = seq.Render(k);
    const bool black = k >= 240 && k < 300;
    EXPECT_EQ(cv::countNonZero(f.bgr.reshape(1)) == 0, black) << k;
    EXPECT_EQ(cv::countNonZero(f.depth16) == 0, black) << k;
    EXPECT_TRUE(f.world_from_cam.Matrix().isApprox(plain.WorldFromCam(k).Matrix())) << k;
    if (!black) {
      EXPECT_GT(cv::countNonZero(f.depth16), 100000) << k;
    }
  }
}

// Viewing direction (camera z axis) in the world at frame k.
Eigen::Vector3d ViewAt(const SyntheticSequence& seq, int k) {
  return seq.WorldFromCam(k).rotation() * Eigen::Vector3d::UnitZ();
}

TEST(SynthRoamTest, TurnsToTheUnseenBackOfTheRoomAndComesBackToTheStart) {
  for (uint64_t seed : {1, 2, 5}) {
    const SyntheticSequence seq(Opts("roam", seed));
    ASSERT_EQ(seq.size(), 900);
    const double deg = 180.0 / M_PI;
    auto angle = [&](int a, int b) {
      return std::acos(std::clamp(ViewAt(seq, a).dot(ViewAt(seq, b)), -1.0, 1.0)) * deg;
    };
    // After the cover (10 s) the camera looks more than a field of view (62 deg) away from every
    // direction it looked in before it (up to 8 s).
    for (int before = 0; before < 240; before += 5)
      EXPECT_GT(angle(before, 300), 75.0) << "seed " << seed << " frame " << before;
    // It faces the back-left corner in the middle (135 deg away) and the front again at the end.
    EXPECT_GT(angle(0, 450), 110.0);
    EXPECT_LT(angle(0, 870), 30.0);
    EXPECT_LT((seq.WorldFromCam(870).translation() - seq.WorldFromCam(0).translation()).norm(),
              1.0);
  }
}

}  // namespace
}  // namespace detslam
