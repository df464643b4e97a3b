#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "detslam/synth/people.h"
#include "detslam/synth/sequence.h"
#include "support/shared_data.h"

namespace detslam {
namespace {

TEST(DataSynthPeopleTest, PhotoCutOutsTextureThePeople) {
  DETSLAM_REQUIRE_SHARED("data/people/person_1.png");
  const std::string dir = detslam::testing::SharedPath("data/people");
  const auto looks = synth::LoadPhotoPeople(dir);
  ASSERT_GE(looks.size(), 2u);
  for (const auto& look : looks) {
    ASSERT_EQ(look.gait.size(), 1u);
    const auto& s = look.gait[0];
    // Cropped to the silhouette: a person is taller than wide and fills much of its box.
    EXPECT_GT(s.bgr.rows, s.bgr.cols);
    EXPECT_GT(cv::countNonZero(s.alpha > 127), s.alpha.total() / 3);
  }
  SynthOptions o;
  o.preset = "walking_xyz";
  o.people_dir = dir;
  o.sensor_noise = false;
  SynthOptions procedural = o;
  procedural.people_dir.clear();
  SyntheticSequence photo(o), proc(procedural);
  double coverage = 0;
  int differing_frames = 0;
  for (int k = 0; k < photo.size(); k += 40) {
    const SynthFrame f = photo.Render(k), g = proc.Render(k);
    coverage += f.Coverage();
    // Same static scene, different people: colours differ only where a person is.
    cv::Mat diff;
    cv::absdiff(f.bgr, g.bgr, diff);
    cv::Mat any_diff;
    cv::cvtColor(diff, any_diff, cv::COLOR_BGR2GRAY);
    const cv::Mat people = (f.instance_mask > 0) | (g.instance_mask > 0);
    EXPECT_EQ(cv::countNonZero((any_diff > 0) & ~people), 0) << "frame " << k;
    differing_frames += cv::countNonZero(any_diff) > 0;
  }
  EXPECT_GT(coverage / ((photo.size() + 39) / 40), 0.05);
  EXPECT_GT(differing_frames, 3);
  // The realistic mode's photo people swing their legs: 8 gait sprites, the photo first, the
  // others differing from it below the hips only.
  const auto walking = synth::LoadPhotoPeople(dir, 8);
  ASSERT_EQ(walking.size(), looks.size());
  for (size_t i = 0; i < walking.size(); ++i) {
    ASSERT_EQ(walking[i].gait.size(), 8u);
    const cv::Mat& photo_alpha = looks[i].gait[0].alpha;
    EXPECT_EQ(cv::norm(walking[i].gait[0].alpha, photo_alpha, cv::NORM_INF), 0.0);
    const int hip = static_cast<int>(0.6 * photo_alpha.rows);
    for (int p = 1; p < 8; ++p) {
      const cv::Mat& a = walking[i].gait[p].alpha;
      EXPECT_EQ(cv::norm(a.rowRange(0, hip), photo_alpha.rowRange(0, hip), cv::NORM_INF), 0.0);
      if (p != 4) {  // phase 4: sin(pi) = 0, no swing
        EXPECT_GT(cv::countNonZero(a.rowRange(hip, a.rows) != photo_alpha.rowRange(hip, a.rows)),
                  100)
            << "look " << i << " phase " << p;
      }
    }
  }
}

}  // namespace
}  // namespace detslam
