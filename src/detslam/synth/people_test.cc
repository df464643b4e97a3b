// Realistic people: swinging legs, turning with the walking direction, a close pass, crossing.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "detslam/synth/camera_path.h"
#include "detslam/synth/people.h"
#include "detslam/synth/renderer.h"
#include "detslam/synth/sequence.h"

namespace detslam {
namespace {

// A photo-like sprite: a body block over two separate legs.
synth::Sprite TwoLeggedSprite() {
  synth::Sprite s;
  s.bgr = cv::Mat(200, 80, CV_8UC3, cv::Scalar(40, 90, 160));
  s.alpha = cv::Mat(200, 80, CV_8U, cv::Scalar(0));
  s.alpha(cv::Rect(10, 0, 60, 120)).setTo(255);  // head and torso: rows 0-119
  s.alpha(cv::Rect(14, 120, 20, 80)).setTo(255);  // left leg
  s.alpha(cv::Rect(46, 120, 20, 80)).setTo(255);  // right leg
  for (int y = 0; y < 200; ++y) s.bgr.row(y).setTo(cv::Scalar(y, 255 - y, 100));
  synth::ComputeSilhouetteRows(&s);
  return s;
}

TEST(SynthPeopleTest, SwungLegsMoveBelowTheHipsOnly) {
  const synth::Sprite photo = TwoLeggedSprite();
  const synth::Sprite same = synth::SwingLegs(photo, 0.0);
  EXPECT_EQ(cv::norm(same.alpha, photo.alpha, cv::NORM_INF), 0.0);
  const synth::Sprite swung = synth::SwingLegs(photo, 0.3);
  const int hip = static_cast<int>(0.6 * photo.alpha.rows);
  // Above the hips nothing changes.
  EXPECT_EQ(cv::norm(swung.alpha.rowRange(0, hip), photo.alpha.rowRange(0, hip), cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(swung.bgr.rowRange(0, hip), photo.bgr.rowRange(0, hip), cv::NORM_INF), 0.0);
  // The legs swing apart at the feet (the left one to the left, the right one to the right) and
  // keep about their area.
  const cv::Mat feet = swung.alpha.row(hip + 70) > 127;  // the legs (80 rows) rise by ~4 rows
  int lo = -1, hi = -1;
  for (int x = 0; x < feet.cols; ++x) {
    if (feet.at<uchar>(0, x)) hi = x, lo = lo < 0 ? x : lo;
  }
  EXPECT_LT(lo, 14 - 5);
  EXPECT_GT(hi, 65 + 5);
  const double before = cv::countNonZero(photo.alpha.rowRange(hip, photo.alpha.rows));
  const double after = cv::countNonZero(swung.alpha.rowRange(hip, photo.alpha.rows));
  EXPECT_NEAR(after / before, 1.0, 0.25);
  EXPECT_EQ(swung.row_mid.size(), photo.row_mid.size());
}

TEST(SynthPeopleTest, RealisticWalkersTurnWithTheirWalkingDirection) {
  const synth::PeopleScript easy("walking_xyz", 1, false), real("walking_xyz", 1, true);
  for (const synth::PersonState& p : easy.At(2.0)) EXPECT_FALSE(p.has_facing);
  int forward = 0, back = 0;
  for (double t = 0; t < 12.0; t += 0.1) {
    const auto before = real.At(t - 0.05), after = real.At(t + 0.05), now = real.At(t);
    for (size_t i = 0; i < now.size(); ++i) {
      ASSERT_TRUE(now[i].has_facing);
      const Eigen::Vector3d step = after[i].foot - before[i].foot;
      if (step.head<2>().norm() < 0.05) continue;  // turning round at an end of the walk
      const Eigen::Vector2d facing(std::cos(now[i].facing_yaw), std::sin(now[i].facing_yaw));
      // Facing where they walk (the sideways sway tilts the step a little).
      EXPECT_GT(facing.dot(step.head<2>().normalized()), 0.8) << "t " << t << " person " << i;
      (facing.x() > 0 ? forward : back)++;
    }
  }
  EXPECT_GT(forward, 20);
  EXPECT_GT(back, 20);
}

TEST(SynthPeopleTest, RealisticWalkersComeCloseAndCrossInFrontOfEachOther) {
  // One walking period (12 s) of walking_xyz seed 1.
  const synth::PeopleScript script("walking_xyz", 1, true);
  const synth::CameraPath path("walking_xyz", 1);
  double closest = 1e9;
  for (double t = 0; t < 12.0; t += 0.05) {
    const Eigen::Vector3d cam = path.WorldFromCam(t).translation();
    for (const synth::PersonState& p : script.At(t)) {
      closest = std::min(closest, (p.foot - cam).head<2>().norm());
    }
  }
  EXPECT_LT(closest, 0.75);
  EXPECT_GT(closest, 0.45);
  // Twice per period the nearer person hides a good part of the other (the far one's pixels
  // with both rendered against with it alone).
  const synth::Scene scene = synth::BuildOfficeScene(1);
  const std::vector<synth::PersonLook> looks = {synth::MakeProceduralPerson(1),
                                                synth::MakeProceduralPerson(2)};
  const PinholeCamera cam = SynthCamera();
  int occluded_frames = 0;
  bool previous = false;
  int occlusions = 0;  // separate stretches
  for (double t = 0; t < 12.0; t += 0.2) {
    const std::vector<synth::PersonState> both = script.At(t);
    const Rigid3d pose = path.WorldFromCam(t);
    const cv::Mat ids = synth::RenderIdeal(scene, looks, both, cam, pose).ids;
    bool occluded = false;
    for (size_t far = 0; far < 2; ++far) {
      const int alone =
          cv::countNonZero(synth::RenderIdeal(scene, looks, {both[far]}, cam, pose).ids);
      const int seen = cv::countNonZero(ids == both[far].id);
      if (alone > 2000 && seen < 0.7 * alone) occluded = true;
    }
    occluded_frames += occluded ? 1 : 0;
    if (occluded && !previous) ++occlusions;
    previous = occluded;
  }
  EXPECT_GE(occlusions, 2) << occluded_frames << " frames";
}

TEST(SynthPeopleTest, SideOnPeopleAreNarrowerAndFromBehindMirrored) {
  // One procedural person 2 m in front of the camera, seen front-on, side-on and from behind.
  const synth::Scene scene = synth::BuildOfficeScene(1);
  const std::vector<synth::PersonLook> looks = {synth::MakeProceduralPerson(3)};
  const PinholeCamera cam = SynthCamera();
  const Rigid3d world_from_cam(synth::LookAtRotation(Eigen::Vector3d(0, -2, 1.0),
                                                     Eigen::Vector3d(0, 0, 1.0)),
                               Eigen::Vector3d(0, -2, 1.0));
  auto render = [&](bool has_facing, double yaw) {
    synth::PersonState p;
    p.id = 1;
    p.foot = Eigen::Vector3d(0, 0, 0);
    p.has_facing = has_facing;
    p.facing_yaw = yaw;
    return synth::RenderIdeal(scene, looks, {p}, cam, world_from_cam).ids == 1;
  };
  const cv::Mat plain = render(false, 0), front = render(true, -M_PI / 2),
                side = render(true, 0.0), behind = render(true, M_PI / 2);
  EXPECT_EQ(cv::norm(front, plain, cv::NORM_INF), 0.0);  // facing the camera: as before
  const double w_front = cv::boundingRect(front).width, w_side = cv::boundingRect(side).width;
  EXPECT_NEAR(w_side / w_front, 0.55, 0.08);
  cv::Mat flipped;
  cv::flip(behind, flipped, 1);
  // Mirrored about the image centre column the camera looks through (within a pixel).
  EXPECT_LT(cv::countNonZero(flipped != front), cv::countNonZero(front) / 20);
}

TEST(SynthPeopleTest, RealisticSittingPresetMovesALaptopButNotInTheTwin) {
  SynthOptions o;
  o.preset = "sitting_static";
  o.seed = 1;
  o.frames = 300;
  o.realism = SynthRealism::kRealistic;
  SynthOptions twin_options = o;
  twin_options.people = false;
  const SyntheticSequence seq(o), twin(twin_options);
  auto laptop = [](const SynthFrame& f) -> const SynthInstance* {
    for (const SynthInstance& in : f.instances)
      if (in.label == "laptop") return &in;
    return nullptr;
  };
  // Frame 0: at rest; frame 200 (6.7 s): pushed 0.45 m to the left (the push starts at 2.5-5 s
  // and takes 1.5 s), about 80 pixels at 1.7 m.
  const SynthFrame a = seq.Render(0), b = seq.Render(200);
  ASSERT_NE(laptop(a), nullptr);
  ASSERT_NE(laptop(b), nullptr);
  EXPECT_GT(laptop(a)->pixels, 3000);
  EXPECT_LT(laptop(b)->box.x, laptop(a)->box.x - 60);
  EXPECT_NEAR(laptop(b)->box.y, laptop(a)->box.y, 12);
  // The twin has the laptop at rest and no instances.
  const SynthFrame ta = twin.Render(0), tb = twin.Render(200);
  EXPECT_TRUE(ta.instances.empty());
  EXPECT_TRUE(tb.instances.empty());
  // The median true depth over the laptop's resting place: unchanged in the twin (the camera
  // moves by millimetres), much farther once the laptop has gone in the sequence.
  const cv::Rect rest = laptop(a)->box;
  auto median = [&](const SynthFrame& f) {
    const cv::Mat roi = f.true_depth(rest).clone();
    std::vector<float> z(roi.begin<float>(), roi.end<float>());
    std::nth_element(z.begin(), z.begin() + z.size() / 2, z.end());
    return z[z.size() / 2];
  };
  EXPECT_NEAR(median(ta), median(tb), 0.02);
  EXPECT_NEAR(median(a), median(ta), 0.02);
  EXPECT_GT(median(b), median(a) + 0.2);
  // The easy mode has no laptop.
  SynthOptions easy = o;
  easy.realism = SynthRealism::kEasy;
  EXPECT_EQ(laptop(SyntheticSequence(easy).Render(200)), nullptr);
}

}  // namespace
}  // namespace detslam
