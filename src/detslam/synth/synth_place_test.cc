// The generator's sequences for place recognition: a depth-scale drift (--depth-scale-bias, the
// loop_long preset), a kidnapped camera (--cut) and look-alike places (the lookalike preset).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "detslam/core/check.h"
#include "detslam/core/rng.h"
#include "detslam/geometry/rigid_ransac.h"
#include "detslam/io/trajectory.h"
#include "detslam/synth/camera_path.h"
#include "detslam/synth/scene.h"
#include "detslam/synth/sequence.h"
#include "detslam/synth/synth_test_util.h"
#include "detslam/synth/writer.h"

namespace detslam {
namespace {

namespace fs = std::filesystem;
using synth_test::Opts;
using synth_test::Slurp;

using synth_test::CheckError;

fs::path PlaceDir(const std::string& name) {
  return synth_test::TempDir("detslam_synth_place_", name);
}

// The InputError message `f` throws ("" if it throws nothing).
template <typename F>
std::string InputErrorOf(F f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// --- options -------------------------------------------------------------------------------------

TEST(SynthPlaceOptionsTest, BadDepthScaleBiasNamesTheOption) {
  for (double bad : {0.6, -0.51, std::numeric_limits<double>::quiet_NaN(),
                     std::numeric_limits<double>::infinity()}) {
    SynthOptions o = Opts("loop");
    o.depth_scale_bias = bad;
    EXPECT_NE(CheckError(o).find("--depth-scale-bias"), std::string::npos) << bad;
    EXPECT_NE(InputErrorOf([&] { SyntheticSequence seq(o); }).find("--depth-scale-bias"),
              std::string::npos);
  }
  for (double good : {0.0, 0.3, -0.2, 0.5}) {
    SynthOptions o = Opts("loop");
    o.depth_scale_bias = good;
    EXPECT_EQ(CheckError(o), "") << good;
  }
}

TEST(SynthPlaceOptionsTest, CutParsesAndBadCutsNameTheOption) {
  SynthOptions o = Opts("loop");
  o.frames = 1050;
  ParseSynthCut("300:900", &o);
  EXPECT_EQ(o.cut_begin, 300);
  EXPECT_EQ(o.cut_end, 900);
  EXPECT_TRUE(o.HasCut());
  EXPECT_EQ(CheckError(o), "");
  for (const std::string bad : {"", "300", "300:", ":900", "900:300", "5:5", "a:b", "-1:5", "1:2:3",
                                "1.5:9", " 1:9", "99999999999:100000000000"}) {
    const std::string error = InputErrorOf([&] { ParseSynthCut(bad, &o); });
    EXPECT_NE(error.find("--cut"), std::string::npos) << "'" << bad << "': " << error;
  }
  // Inside the sequence, at least one frame on each side: 1 <= A < B <= frames - 1.
  o.frames = 100;
  for (const auto& [a, b] : std::vector<std::pair<int, int>>{{0, 10}, {50, 100}, {90, 200}}) {
    o.cut_begin = a;
    o.cut_end = b;
    EXPECT_NE(CheckError(o).find("--cut"), std::string::npos) << a << ":" << b;
    EXPECT_NE(CheckError(o).find("99"), std::string::npos) << CheckError(o);
    EXPECT_NE(InputErrorOf([&] { SyntheticSequence seq(o); }).find("--cut"), std::string::npos);
  }
  o.cut_begin = 1;
  o.cut_end = 99;
  EXPECT_EQ(CheckError(o), "");
  o.frames = -1;  // the preset's 900 frames
  o.cut_end = 900;
  EXPECT_NE(CheckError(o).find("--cut"), std::string::npos);
  o.cut_end = 899;
  EXPECT_EQ(CheckError(o), "");
  o.preset = "no_such_preset";  // the frame count is unknown: only A < B is checked here
  EXPECT_EQ(CheckError(o).find("--cut"), std::string::npos);
  o.cut_end = 0;
  EXPECT_NE(CheckError(o).find("--cut"), std::string::npos);
}

// --- depth scale drift -----------------------------------------------------------------------

TEST(SynthDepthScaleTest, RampsFromOneToOnePlusBiasAndBack) {
  const int n = 901;
  EXPECT_EQ(SynthDepthScale(0.0, 450, n), 1.0);
  EXPECT_DOUBLE_EQ(SynthDepthScale(0.3, 0, n), 1.0);
  EXPECT_NEAR(SynthDepthScale(0.3, n - 1, n), 1.0, 1e-15);
  EXPECT_DOUBLE_EQ(SynthDepthScale(0.3, 450, n), 1.3);
  EXPECT_NEAR(SynthDepthScale(0.3, 225, n), 1.15, 1e-12);  // sin^2(pi / 4) = 1/2
  for (int k = 1; k <= 450; ++k)
    EXPECT_GT(SynthDepthScale(0.3, k, n), SynthDepthScale(0.3, k - 1, n));
  for (int k = 451; k < n; ++k)
    EXPECT_LT(SynthDepthScale(0.3, k, n), SynthDepthScale(0.3, k - 1, n));
}

TEST(SynthDepthScaleTest, ScalesTheWrittenDepthOnly) {
  SynthOptions biased = Opts("loop", 2, /*noise=*/false);
  biased.frames = 61;
  biased.depth_scale_bias = 0.3;
  SynthOptions plain = biased;
  plain.depth_scale_bias = 0.0;
  SyntheticSequence a(biased), b(plain);
  for (int k : {0, 15, 30, 60}) {
    const SynthFrame fa = a.Render(k), fb = b.Render(k);
    const double scale = a.DepthScaleOf(k);
    EXPECT_DOUBLE_EQ(scale, SynthDepthScale(0.3, k, 61));
    EXPECT_EQ(b.DepthScaleOf(k), 1.0);
    // Pose, colour, masks and the true depth are those of the unbiased sequence.
    EXPECT_TRUE(fa.world_from_cam.Matrix().isApprox(fb.world_from_cam.Matrix(), 0.0));
    EXPECT_EQ(cv::norm(fa.bgr, fb.bgr, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(fa.true_depth, fb.true_depth, cv::NORM_INF), 0.0);
    int checked = 0;
    for (int v = 0; v < fa.depth16.rows; v += 7) {
      for (int u = 0; u < fa.depth16.cols; u += 7) {
        const uint16_t raw = fa.depth16.at<uint16_t>(v, u);
        if (raw == 0) continue;
        EXPECT_NEAR(raw / 5000.0, scale * fa.true_depth.at<float>(v, u), 1.5e-4);
        ++checked;
      }
    }
    EXPECT_GT(checked, 3000);
  }
  EXPECT_DOUBLE_EQ(a.DepthScaleOf(30), 1.3);
}

// Where a visual odometry that trusts the biased depth believes the camera is: each step of the
// true path scaled by that frame's depth scale. Returns how far that estimate at frame `revisit`
// is from the estimate at frame 0 (the truth: 0, the camera is back at its start).
double DeadReckoningGapAtRevisit(const std::string& preset, double bias, int revisit) {
  SynthOptions o = Opts(preset);
  o.depth_scale_bias = bias;
  const int n = SynthFrameCount(o);
  synth::CameraPath path(preset, 1);
  Eigen::Vector3d est = Eigen::Vector3d::Zero();
  for (int k = 0; k < revisit; ++k) {
    const Eigen::Vector3d step =
        path.WorldFromCam((k + 1) / 30.0).translation() - path.WorldFromCam(k / 30.0).translation();
    est += SynthDepthScale(bias, k, n) * step;
  }
  return (est -
          (path.WorldFromCam(revisit / 30.0).translation() - path.WorldFromCam(0.0).translation()))
      .norm();
}

TEST(SynthDepthScaleTest, LoopLongDriftsPastLoopSearchRadiusWhereLoopCannot) {
  // A loop detector that looks for candidates within 1.5 m of the estimated position: on `loop`
  // (3.2 x 2.0 m circuit) even a 30 % bias moves the estimate at the revisit by < 1 m, on
  // loop_long (9.0 x 5.2 m) 25 % move it by > 1.5 m (in scale-following odometry).
  const int loop_revisit = static_cast<int>(synth::CameraPath::kLoopPeriod * 30);
  const int long_revisit = static_cast<int>(synth::CameraPath::kLoopLongPeriod * 30);
  EXPECT_LT(DeadReckoningGapAtRevisit("loop", 0.3, 899), 1.0);
  EXPECT_GT(DeadReckoningGapAtRevisit("loop_long", 0.25, long_revisit), 1.6);
  EXPECT_GT(DeadReckoningGapAtRevisit("loop_long", 0.3, long_revisit), 2.0);
  EXPECT_LT(DeadReckoningGapAtRevisit("loop_long", 0.0, long_revisit), 1e-9);
  EXPECT_LT(loop_revisit, 1000);
}

TEST(SynthLoopLongTest, ClosedCircuitInsideTheLargeRoom) {
  synth::CameraPath path("loop_long", 3);
  const double period = synth::CameraPath::kLoopLongPeriod;
  const Rigid3d back = path.WorldFromCam(0).Inverse() * path.WorldFromCam(period);
  EXPECT_LT(back.translation().norm(), 1e-9);
  EXPECT_LT(back.RotationAngle(), 1e-9);
  // The default length is one lap plus 3 s over the start again.
  EXPECT_EQ(SynthPresetDefaultFrames("loop_long"), static_cast<int>(period * 30) + 90);
  // The circuit is longer than loop's by far, and keeps 0.8 m from every piece of furniture.
  const synth::Scene scene = synth::BuildLargeOfficeScene(3);
  ASSERT_GT(scene.boxes.size(), 30u);
  double length = 0, min_clearance = 1e9;
  for (int k = 0; k < static_cast<int>(period * 30); ++k) {
    const Eigen::Vector3d p = path.WorldFromCam(k / 30.0).translation();
    length += (path.WorldFromCam((k + 1) / 30.0).translation() - p).norm();
    for (size_t i = 1; i < scene.boxes.size(); ++i) {
      const Eigen::Vector3d lo = scene.boxes[i].lo.cast<double>(),
                            hi = scene.boxes[i].hi.cast<double>();
      min_clearance = std::min(min_clearance, (p - p.cwiseMax(lo).cwiseMin(hi)).norm());
    }
  }
  EXPECT_GT(length, 20.0);
  EXPECT_GT(min_clearance, 0.8);
  // Most of the view has depth (the furnished walls are in the sensor's range).
  SyntheticSequence seq(Opts("loop_long", 3, false));
  for (int k = 0; k < seq.size(); k += 400) {
    const SynthFrame f = seq.Render(k);
    EXPECT_GT(cv::countNonZero(f.depth16) / static_cast<double>(f.depth16.total()), 0.85) << k;
  }
}

// --- kidnapped camera ------------------------------------------------------------------------

TEST(SynthCutTest, CutFramesAreAbsentFromEveryFileAndTheRestUnchanged) {
  SynthOptions o = Opts("walking_xyz", 4);
  o.frames = 9;
  SynthOptions cut = o;
  ParseSynthCut("3:7", &cut);
  const fs::path full_dir = PlaceDir("full"), cut_dir = PlaceDir("cut");
  WriteSequence(o, full_dir.string());
  const SynthStats stats = WriteSequence(cut, cut_dir.string());
  EXPECT_EQ(stats.frames, 5);
  SyntheticSequence seq(o);
  const std::vector<int> kept = {0, 1, 2, 7, 8};
  // Ground truth: the kept frames' true stamps and poses (a 4/30 s gap, a jump in pose).
  const Trajectory gt = ReadTumTrajectory((cut_dir / "groundtruth.txt").string());
  ASSERT_EQ(gt.size(), kept.size());
  for (size_t i = 0; i < kept.size(); ++i) {
    EXPECT_EQ(gt[i].stamp, seq.StampOf(kept[i]));
    EXPECT_TRUE(gt[i].world_from_cam.Matrix().isApprox(seq.WorldFromCam(kept[i]).Matrix(), 1e-8));
  }
  // Every per-frame file of a kept frame is the uncut run's; nothing of a cut frame exists.
  int files = 0;
  for (const auto& entry : fs::recursive_directory_iterator(cut_dir)) {
    if (!entry.is_regular_file() || entry.path().extension() != ".png") continue;
    EXPECT_EQ(Slurp(entry.path()), Slurp(full_dir / fs::relative(entry.path(), cut_dir)));
    ++files;
  }
  EXPECT_EQ(files, 3 * 5);
  for (int k = 3; k < 7; ++k) {
    const std::string stamp = seq.StampOf(k).ToString();
    EXPECT_FALSE(fs::exists(cut_dir / "rgb" / (stamp + ".png")));
    EXPECT_FALSE(fs::exists(cut_dir / "masks" / (stamp + ".png")));
    EXPECT_FALSE(fs::exists(cut_dir / "depth" / (seq.DepthStampOf(k).ToString() + ".png")));
    for (const char* list : {"rgb.txt", "depth.txt", "masks/instances.txt"}) {
      EXPECT_EQ(Slurp(cut_dir / list).find(stamp), std::string::npos) << list << " " << k;
    }
  }
  for (int k : kept) {
    EXPECT_NE(Slurp(cut_dir / "rgb.txt").find(seq.StampOf(k).ToString()), std::string::npos);
    EXPECT_NE(Slurp(cut_dir / "depth.txt").find(seq.DepthStampOf(k).ToString()), std::string::npos);
  }
  EXPECT_NE(Slurp(cut_dir / "rgb.txt").find("--cut 3:7"), std::string::npos);
  fs::remove_all(full_dir);
  fs::remove_all(cut_dir);
}

// Fraction of frame `target`'s pixels (a grid) that some frame in [0, before) saw (projects inside
// its image at the depth it measured there).
double SeenBefore(const SyntheticSequence& seq, int target, int before, int step) {
  const PinholeCamera cam = seq.camera();
  const SynthFrame t = seq.Render(target);
  std::vector<Eigen::Vector3d> points;
  for (int v = 8; v < cam.height; v += 16) {
    for (int u = 8; u < cam.width; u += 16) {
      const float z = t.true_depth.at<float>(v, u);
      if (z > 0) points.push_back(t.world_from_cam * cam.Unproject(Eigen::Vector2d(u, v), z));
    }
  }
  std::vector<bool> seen(points.size(), false);
  for (int k = 0; k < before; k += step) {
    const SynthFrame f = seq.Render(k);
    const Rigid3d cam_from_world = f.world_from_cam.Inverse();
    for (size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector3d p = cam_from_world * points[i];
      if (seen[i] || p.z() < 0.1) continue;
      const Eigen::Vector2d uv = cam.Project(p);
      const int u = static_cast<int>(std::lround(uv.x())),
                v = static_cast<int>(std::lround(uv.y()));
      if (u < 0 || v < 0 || u >= cam.width || v >= cam.height) continue;
      seen[i] = std::abs(f.true_depth.at<float>(v, u) - p.z()) < 0.03;
    }
  }
  return static_cast<double>(std::count(seen.begin(), seen.end(), true)) / points.size();
}

TEST(SynthCutTest, RecommendedKidnapLandsOnMappedPlaceFromAnotherViewpoint) {
  // README: detslam synth --preset walking_halfsphere --seed 1 --cut 150:510. The camera maps the
  // table from one stretch of the half-sphere for 5 s, then jumps 12 s ahead to another.
  SyntheticSequence seq(Opts("walking_halfsphere", 1, false));
  const int a = 150, b = 510;
  const Rigid3d landing = seq.WorldFromCam(b);
  double nearest = 1e9, nearest_angle = 1e9;
  for (int k = 0; k < a; ++k) {
    const Rigid3d rel = seq.WorldFromCam(k).Inverse() * landing;
    nearest = std::min(nearest, rel.translation().norm());
    nearest_angle = std::min(nearest_angle, rel.RotationAngle() * 180.0 / M_PI);
  }
  EXPECT_GT(nearest, 0.5);         // metres from every pose before the cut
  EXPECT_GT(nearest_angle, 10.0);  // degrees
  EXPECT_GT((seq.WorldFromCam(a - 1).translation() - landing.translation()).norm(), 0.5);
  // Most of what it sees after the jump was seen (mapped) before the cut.
  EXPECT_GT(SeenBefore(seq, b, a, 10), 0.7);
}

// --- look-alike places -----------------------------------------------------------------------

TEST(SynthLookalikeTest, TwinsShareTexturesNotPlacement) {
  for (uint64_t seed : {1, 2, 3}) {
    const synth::LookalikeScene ls = synth::BuildLookalikeScene(seed);
    ASSERT_EQ(ls.twins.size(), 28u);
    std::vector<Eigen::Vector3f> moves;
    for (const auto& [i, j] : ls.twins) {
      const synth::SceneBox &first = ls.scene.boxes[i], &second = ls.scene.boxes[j];
      EXPECT_EQ(first.texture, second.texture);
      EXPECT_LT(first.hi.x(), synth::LookalikeScene::kFirstPartMaxX);
      EXPECT_GT(second.lo.x(), synth::LookalikeScene::kSecondPartMinX);
      // Different size, and each face's texture covers the face.
      EXPECT_GT((first.hi - first.lo - (second.hi - second.lo)).cwiseAbs().maxCoeff(), 0.01f);
      for (const synth::SceneBox* box : {&first, &second}) {
        const cv::Mat& front = ls.scene.textures[box->texture[synth::FaceIndex(1, false)]];
        EXPECT_GE(front.cols, (box->hi.x() - box->lo.x()) * synth::kTexelsPerMetre);
        EXPECT_GE(front.rows, (box->hi.z() - box->lo.z()) * synth::kTexelsPerMetre);
      }
      // Front texture origin (FaceTexel: column from lo.x, row from hi.z) moves by this.
      moves.push_back(Eigen::Vector3f(second.lo.x(), second.lo.y(), second.hi.z()) -
                      Eigen::Vector3f(first.lo.x(), first.lo.y(), first.hi.z()));
    }
    // No rigid motion carries two twins onto each other: they all move differently.
    for (size_t i = 0; i < moves.size(); ++i) {
      for (size_t k = i + 1; k < moves.size(); ++k) EXPECT_GT((moves[i] - moves[k]).norm(), 0.25f);
    }
    // No other box uses a twin's texture.
    std::vector<int> users(ls.scene.textures.size(), 0);
    for (const auto& box : ls.scene.boxes) {
      for (int t : box.texture) ++users[t];
    }
    for (const auto& [i, j] : ls.twins) {
      for (int t : ls.scene.boxes[i].texture) EXPECT_EQ(users[t], 2);
    }
  }
}

TEST(SynthLookalikeTest, SecondPartNeverSeesTheFirst) {
  SyntheticSequence seq(Opts("lookalike", 2, false));
  const PinholeCamera cam = seq.camera();
  ASSERT_EQ(seq.size(), 1350);
  // Back-projected pixels: the first part (x < -0.9) is out of view from 65 % of the script on,
  // the second part (x > 0.9) until 35 %.
  for (int k = 0; k < seq.size(); k += 45) {
    const double u = k / (30.0 * synth::CameraPath::kLookalikeDuration);
    if (u > 0.35 && u < 0.65) continue;
    const SynthFrame f = seq.Render(k);
    double min_x = 1e9, max_x = -1e9;
    for (int v = 0; v < cam.height; v += 4) {
      for (int c = 0; c < cam.width; c += 4) {
        const float z = f.true_depth.at<float>(v, c);
        const Eigen::Vector3d p = f.world_from_cam * cam.Unproject(Eigen::Vector2d(c, v), z);
        min_x = std::min(min_x, p.x());
        max_x = std::max(max_x, p.x());
      }
    }
    if (u >= 0.65) {
      EXPECT_GT(min_x, synth::LookalikeScene::kFirstPartMaxX) << "frame " << k;
    } else {
      EXPECT_LT(max_x, synth::LookalikeScene::kSecondPartMinX) << "frame " << k;
    }
  }
}

struct PairMatch {
  int matches = 0;        // mutual nearest ORB neighbours (Hamming <= 40) with depth in both
  int rigid_inliers = 0;  // largest set one rigid motion explains (3 cm)
};

// Matches ORB features of two frames and finds the largest rigidly consistent subset of the
// matches' 3-D points (each in its own camera frame).
PairMatch MatchFrames(const SynthFrame& a, const SynthFrame& b, const PinholeCamera& cam) {
  cv::Ptr<cv::ORB> orb = cv::ORB::create(1000);
  std::vector<cv::KeyPoint> ka, kb;
  cv::Mat da, db, ga, gb;
  cv::cvtColor(a.bgr, ga, cv::COLOR_BGR2GRAY);
  cv::cvtColor(b.bgr, gb, cv::COLOR_BGR2GRAY);
  orb->detectAndCompute(ga, cv::noArray(), ka, da);
  orb->detectAndCompute(gb, cv::noArray(), kb, db);
  cv::BFMatcher matcher(cv::NORM_HAMMING, /*crossCheck=*/true);
  std::vector<cv::DMatch> matches;
  matcher.match(da, db, matches);
  std::vector<Eigen::Vector3d> pa, pb;
  for (const cv::DMatch& m : matches) {
    if (m.distance > 40) continue;
    const cv::Point2f ua = ka[m.queryIdx].pt, ub = kb[m.trainIdx].pt;
    const float za = a.true_depth.at<float>(cvRound(ua.y), cvRound(ua.x));
    const float zb = b.true_depth.at<float>(cvRound(ub.y), cvRound(ub.x));
    if (za <= 0 || zb <= 0) continue;
    pa.push_back(cam.Unproject(Eigen::Vector2d(ua.x, ua.y), za));
    pb.push_back(cam.Unproject(Eigen::Vector2d(ub.x, ub.y), zb));
  }
  PairMatch out;
  out.matches = static_cast<int>(pa.size());
  RansacOptions ransac;
  ransac.max_iterations = 2000;
  ransac.min_inliers = 3;
  Rng rng(5);
  out.rigid_inliers = EstimateRigidRansac(pa, pb, 0.03, ransac, rng).num_inliers;
  return out;
}

TEST(SynthLookalikeTest, PartsLookAlikeButDoNotAlignRigidly) {
  SyntheticSequence seq(Opts("lookalike", 1, true));
  SyntheticSequence office(Opts("static", 1, true));
  const PinholeCamera cam = seq.camera();
  // The same moment of the sway in the first and the second part, and a true revisit: the
  // first part 1 s later.
  int alike_matches = 0, alike_inliers = 0, revisit_inliers = 1 << 30, other_matches = 0;
  for (int k : {0, 120, 240}) {
    const SynthFrame first = seq.Render(k), second = seq.Render(seq.size() - 1 - k);
    const PairMatch alike = MatchFrames(first, second, cam);
    const PairMatch revisit = MatchFrames(first, seq.Render(k + 30), cam);
    const PairMatch other = MatchFrames(first, office.Render(k), cam);
    alike_matches += alike.matches;
    alike_inliers = std::max(alike_inliers, alike.rigid_inliers);
    revisit_inliers = std::min(revisit_inliers, revisit.rigid_inliers);
    other_matches += other.matches;
    std::printf("frame %d: alike %d matches, %d rigid; revisit %d / %d; other room %d / %d\n", k,
                alike.matches, alike.rigid_inliers, revisit.matches, revisit.rigid_inliers,
                other.matches, other.rigid_inliers);
  }
  // Many more matches between the parts than with another room (same generator, other textures)
  // ...
  EXPECT_GT(alike_matches, 120);
  EXPECT_GT(alike_matches, 10 * std::max(1, other_matches));
  // ... but one rigid motion explains few of them (one item's worth), a true revisit most.
  EXPECT_LE(alike_inliers, 25);
  EXPECT_GT(revisit_inliers, 5 * alike_inliers);
}

}  // namespace
}  // namespace detslam
