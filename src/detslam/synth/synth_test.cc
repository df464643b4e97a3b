#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>

#include "detslam/core/check.h"
#include "detslam/synth/camera_path.h"
#include "detslam/synth/scene.h"
#include "detslam/synth/sequence.h"
#include "detslam/synth/synth_test_util.h"
#include "detslam/synth/writer.h"

namespace detslam {
namespace {

using synth_test::Opts;

std::string Png(const cv::Mat& m) {
  std::vector<uchar> buf;
  EXPECT_TRUE(cv::imencode(".png", m, buf));
  return std::string(buf.begin(), buf.end());
}

// Distance from p to the surface of box b (seen from outside, or from inside for the room).
double SurfaceDistance(const synth::SceneBox& b, const Eigen::Vector3d& p) {
  const Eigen::Vector3d lo = b.lo.cast<double>(), hi = b.hi.cast<double>();
  const bool inside = (p.array() >= lo.array()).all() && (p.array() <= hi.array()).all();
  if (inside) {
    return std::min((p - lo).minCoeff(), (hi - p).minCoeff());
  }
  const Eigen::Vector3d clamped = p.cwiseMax(lo).cwiseMin(hi);
  return (p - clamped).norm();
}

TEST(SynthOptionsTest, UnknownPresetIsAnInputErrorListingValidOnes) {
  SynthOptions o = Opts("walking_sideways");
  std::string error;
  EXPECT_FALSE(o.Check(&error));
  EXPECT_NE(error.find("walking_xyz"), std::string::npos);
  try {
    SyntheticSequence seq(o);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("walking_halfsphere"), std::string::npos) << e.what();
  }
  EXPECT_EQ(SynthPresetNames().size(), 10u);
}

TEST(SynthOptionsTest, RealismAndItsAblationsParseOrNameTheBadValue) {
  EXPECT_EQ(ParseSynthRealism("easy"), SynthRealism::kEasy);
  EXPECT_EQ(ParseSynthRealism("realistic"), SynthRealism::kRealistic);
  EXPECT_STREQ(SynthRealismName(SynthRealism::kRealistic), "realistic");
  try {
    ParseSynthRealism("kinect");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("realistic, easy"), std::string::npos) << e.what();
  }
  SynthOptions o = Opts("static");
  ParseSynthRealismOff("noise,timing,noise", &o);
  EXPECT_EQ(o.realism_off, (std::vector<std::string>{"noise", "timing"}));
  EXPECT_TRUE(o.RealismOff("timing"));
  EXPECT_FALSE(o.RealismOff("blur"));
  std::string error;
  EXPECT_FALSE(o.Check(&error)) << "ablations need the realistic mode";
  EXPECT_NE(error.find("--realism-off"), std::string::npos);
  o.realism = SynthRealism::kRealistic;
  EXPECT_TRUE(o.Check(&error)) << error;
  for (const std::string bad : {"", "noise,", "Noise", "noise,,blur"}) {
    SynthOptions p = Opts("static");
    try {
      ParseSynthRealismOff(bad, &p);
      FAIL() << "expected InputError for '" << bad << "'";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("dropouts"), std::string::npos) << e.what();
    }
  }
  // Every effect switched off changes the frames, except where the scene leaves it nothing to do.
  o.frames = 30;
  o.preset = "walking_xyz";
  o.realism_off.clear();
  const SynthFrame full = SyntheticSequence(o).Render(25);
  // The sequence's camera states its rolling shutter (settings.yaml), none where it is off.
  EXPECT_DOUBLE_EQ(SyntheticSequence(o).camera().rolling_shutter_readout,
                   synth::ColourCameraModel{}.readout_s);
  EXPECT_DOUBLE_EQ(SyntheticSequence(Opts("static")).camera().rolling_shutter_readout, 0.0);
  for (const std::string& effect : SynthRealismEffects()) {
    SynthOptions p = o;
    p.realism_off = {effect};
    if (effect == "shutter") {
      EXPECT_DOUBLE_EQ(SyntheticSequence(p).camera().rolling_shutter_readout, 0.0);
    }
    const SynthFrame f = SyntheticSequence(p).Render(25);
    const bool colour_differs = cv::norm(f.bgr, full.bgr, cv::NORM_INF) > 0;
    const bool depth_differs = cv::norm(f.depth16, full.depth16, cv::NORM_INF) > 0;
    EXPECT_TRUE(colour_differs || depth_differs) << effect;
    const bool colour_effect = effect == "shutter" || effect == "blur" || effect == "colour";
    if (colour_effect) {
      EXPECT_TRUE(colour_differs) << effect;
    }
    if (effect == "dropouts") {
      EXPECT_GT(cv::countNonZero(f.depth16), cv::countNonZero(full.depth16) * 1.3);
    }
  }
}

TEST(SynthSequenceTest, DepthBackProjectsOntoSceneSurfaces) {
  SynthOptions o = Opts("static", 3, /*noise=*/false);
  SyntheticSequence seq(o);
  const synth::Scene scene = synth::BuildOfficeScene(o.seed);
  const PinholeCamera cam = seq.camera();
  for (int k : {0, 137}) {
    const SynthFrame f = seq.Render(k);
    int checked = 0;
    for (int v = 3; v < cam.height; v += 23) {
      for (int u = 5; u < cam.width; u += 29) {
        const uint16_t raw = f.depth16.at<uint16_t>(v, u);
        if (raw == 0) continue;
        const double z = raw / cam.depth_map_factor;
        EXPECT_NEAR(z, f.true_depth.at<float>(v, u), 1.0 / cam.depth_map_factor);
        const Eigen::Vector3d p_world = f.world_from_cam * cam.Unproject(Eigen::Vector2d(u, v), z);
        double best = 1e9;
        for (const auto& b : scene.boxes) best = std::min(best, SurfaceDistance(b, p_world));
        // Quantisation (0.1 mm along z) plus float ray casting.
        EXPECT_LT(best, 2e-3) << "pixel " << u << "," << v << " frame " << k;
        ++checked;
      }
    }
    EXPECT_GT(checked, 300);
  }
}

TEST(SynthSequenceTest, MaskCoversExactlyThePeopleAndTwinHasSamePoses) {
  SynthOptions with = Opts("walking_xyz", 5, false);
  SynthOptions without = with;
  without.people = false;
  SyntheticSequence a(with), b(without);
  ASSERT_EQ(a.size(), b.size());
  int frames_with_people = 0;
  for (int k = 0; k < a.size(); k += 97) {
    const SynthFrame fa = a.Render(k), fb = b.Render(k);
    EXPECT_EQ(fa.world_from_cam.translation(), fb.world_from_cam.translation());
    EXPECT_TRUE(fa.world_from_cam.rotation().isApprox(fb.world_from_cam.rotation(), 0.0));
    EXPECT_EQ(cv::countNonZero(fb.instance_mask), 0);
    EXPECT_TRUE(fb.instances.empty());
    int mask_px = 0, mismatched = 0;
    for (int v = 0; v < fa.true_depth.rows; ++v) {
      for (int u = 0; u < fa.true_depth.cols; ++u) {
        const float za = fa.true_depth.at<float>(v, u), zb = fb.true_depth.at<float>(v, u);
        const bool in_mask = fa.instance_mask.at<uint16_t>(v, u) != 0;
        const bool differs = std::abs(za - zb) > 1e-5f;
        mask_px += in_mask;
        // Mask pixels carry the (nearer) person's depth; elsewhere the scene is untouched.
        if (in_mask != differs || (in_mask && !(za < zb))) ++mismatched;
      }
    }
    EXPECT_EQ(mismatched, 0) << "frame " << k;
    int listed = 0;
    for (const auto& in : fa.instances) {
      listed += in.pixels;
      EXPECT_GE(in.id, 1);
      EXPECT_LE(in.id, 2);
      EXPECT_EQ(in.label, "person");
      EXPECT_EQ(cv::countNonZero(fa.instance_mask(in.box) == in.id), in.pixels);
    }
    EXPECT_EQ(listed, mask_px);
    frames_with_people += mask_px > 0;
  }
  EXPECT_GE(frames_with_people, 3);
  for (int k = 0; k < a.size(); k += 31) {
    EXPECT_TRUE(a.WorldFromCam(k).Matrix().isApprox(b.WorldFromCam(k).Matrix(), 0.0));
  }
}

TEST(SynthSequenceTest, SameSeedSameBytesDifferentSeedDifferentBytes) {
  SyntheticSequence a(Opts("walking_halfsphere", 7)), b(Opts("walking_halfsphere", 7)),
      c(Opts("walking_halfsphere", 8));
  for (int k : {0, 45}) {
    const SynthFrame fa = a.Render(k), fb = b.Render(k), fc = c.Render(k);
    EXPECT_EQ(Png(fa.bgr), Png(fb.bgr));
    EXPECT_EQ(Png(fa.depth16), Png(fb.depth16));
    EXPECT_EQ(Png(fa.instance_mask), Png(fb.instance_mask));
    EXPECT_NE(Png(fa.bgr), Png(fc.bgr));
    EXPECT_NE(Png(fa.depth16), Png(fc.depth16));
  }
  // Rendering a frame again (after others) gives the same bytes: no hidden state.
  EXPECT_EQ(Png(a.Render(0).bgr), Png(b.Render(0).bgr));
}

// --scene-seed: the room's textures follow the scene seed, the camera path follows the seed.
TEST(SynthSequenceTest, SceneSeedKeepsTheRoomAndSeedMovesTheCamera) {
  SynthOptions one = Opts("static", 1), two_in_one = Opts("static", 2), two = Opts("static", 2);
  two_in_one.scene_seed = 1;
  for (SynthOptions* o : {&one, &two_in_one, &two}) {
    o->sensor_noise = false;
    o->people = false;
  }
  const SyntheticSequence a(one), b(two_in_one), c(two);
  EXPECT_GT((a.WorldFromCam(30).translation() - b.WorldFromCam(30).translation()).norm(), 1e-3);
  EXPECT_EQ((b.WorldFromCam(30).translation() - c.WorldFromCam(30).translation()).norm(), 0.0);
  const SynthFrame fb = b.Render(30), fc = c.Render(30);
  EXPECT_EQ(cv::norm(fb.true_depth, fc.true_depth, cv::NORM_INF), 0.0);  // same geometry, pose
  EXPECT_NE(Png(fb.bgr), Png(fc.bgr));                                   // other textures
  EXPECT_EQ(b.options().SceneSeed(), 1u);
  EXPECT_EQ(c.options().SceneSeed(), 2u);
}

TEST(SynthSequenceTest, EveryPresetHasManyFastCorners) {
  for (const std::string& preset : SynthPresetNames()) {
    SyntheticSequence seq(Opts(preset, 2));
    int min_corners = 1 << 30;
    for (int k = 0; k < seq.size(); k += seq.size() / 4) {
      min_corners = std::min(min_corners, CountFastCorners(seq.Render(k).bgr));
    }
    EXPECT_GT(min_corners, 1000) << preset;
  }
}

TEST(SynthSequenceTest, PeopleCoverTenToFiftyPercentInWalkingPresets) {
  for (const std::string preset :
       {"walking_xyz", "walking_static", "walking_rpy", "walking_halfsphere"}) {
    SyntheticSequence seq(Opts(preset, 1, false));
    double sum = 0;
    int n = 0, max_people = 0;
    for (int k = 0; k < seq.size(); k += 15, ++n) {
      const SynthFrame f = seq.Render(k);
      sum += f.Coverage();
      max_people = std::max(max_people, static_cast<int>(f.instances.size()));
    }
    EXPECT_GT(sum / n, 0.10) << preset;
    EXPECT_LT(sum / n, 0.50) << preset;
    EXPECT_EQ(max_people, 2) << preset;
  }
  SyntheticSequence none(Opts("static"));
  EXPECT_EQ(none.Render(10).Coverage(), 0.0);
}

TEST(SynthSequenceTest, DepthNoiseAndHolesFollowTheSensorModel) {
  SyntheticSequence seq(Opts("walking_static", 4, true));
  const SynthFrame f = seq.Render(20);
  const synth::SensorModel model;
  int valid = 0, holes = 0, in_range = 0;
  double sum_sq_norm = 0;
  for (int v = 0; v < f.depth16.rows; ++v) {
    for (int u = 0; u < f.depth16.cols; ++u) {
      const double z = f.true_depth.at<float>(v, u);
      if (z < model.min_depth || z > model.max_depth) {
        EXPECT_EQ(f.depth16.at<uint16_t>(v, u), 0);
        continue;
      }
      ++in_range;
      const uint16_t raw = f.depth16.at<uint16_t>(v, u);
      if (raw == 0) {
        ++holes;
        continue;
      }
      const double sigma =
          model.sigma0 + model.sigma2 * (z - model.z_offset) * (z - model.z_offset);
      const double e = (raw / 5000.0 - z) / sigma;
      sum_sq_norm += e * e;
      ++valid;
    }
  }
  ASSERT_GT(valid, 100000);
  // Normalised errors have unit variance (quantisation adds a little).
  EXPECT_NEAR(std::sqrt(sum_sq_norm / valid), 1.0, 0.15);
  const double hole_fraction = static_cast<double>(holes) / in_range;
  EXPECT_GT(hole_fraction, 0.01);
  EXPECT_LT(hole_fraction, 0.10);
  // Colour noise: the noisy image differs slightly from the ideal rendering.
  SynthOptions clean = Opts("walking_static", 4, false);
  const SynthFrame g = SyntheticSequence(clean).Render(20);
  cv::Mat diff;
  cv::absdiff(f.bgr, g.bgr, diff);
  const double mean_abs = cv::mean(diff)[0];
  EXPECT_GT(mean_abs, 0.8);  // E|N(0, 2)| = 1.6
  EXPECT_LT(mean_abs, 2.5);
}

TEST(SynthSequenceTest, StampsAndMotionAreRealistic) {
  for (const std::string& preset : SynthPresetNames()) {
    SyntheticSequence seq(Opts(preset));
    double max_speed = 0, max_rate = 0;
    for (int k = 1; k < seq.size(); ++k) {
      // 30 Hz in whole microseconds: 1/30 s rounded, never drifting.
      EXPECT_NEAR(seq.StampOf(k).ns - seq.StampOf(k - 1).ns, 1e9 / 30.0, 1000.0) << preset;
      EXPECT_EQ(seq.StampOf(k).ns % 1000, 0);
      EXPECT_NEAR(seq.StampOf(k).ns - seq.StampOf(0).ns, k * 1e9 / 30.0, 500.0);
      const double offset = AbsDiffSeconds(seq.DepthStampOf(k), seq.StampOf(k));
      EXPECT_GT(offset, 0.001);
      EXPECT_LT(offset, 0.02);
      const Rigid3d delta = seq.WorldFromCam(k - 1).Inverse() * seq.WorldFromCam(k);
      max_speed = std::max(max_speed, delta.translation().norm() * 30.0);
      max_rate = std::max(max_rate, delta.RotationAngle() * 30.0 * 180.0 / M_PI);
    }
    EXPECT_LT(max_speed, 0.6) << preset;  // m/s
    // deg/s; roam turns 135 deg in 4 s (a quick hand-held turn, peak ~58 deg/s; TUM's fr1/360
    // averages 41 deg/s)
    EXPECT_LT(max_rate, preset == "roam" ? 65.0 : 40.0) << preset;
  }
  // The loop returns to its start.
  synth::CameraPath loop("loop", 1);
  const Rigid3d end =
      loop.WorldFromCam(0).Inverse() * loop.WorldFromCam(synth::CameraPath::kLoopPeriod);
  EXPECT_LT(end.translation().norm(), 1e-9);
  EXPECT_LT(end.RotationAngle(), 1e-9);
}

}  // namespace
}  // namespace detslam
