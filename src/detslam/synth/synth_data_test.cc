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
}

}  // namespace
}  // namespace detslam
