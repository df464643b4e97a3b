#include "detslam/synth/realistic_sensor.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "detslam/synth/renderer.h"
#include "detslam/synth/scene.h"
#include "detslam/synth/sequence.h"

namespace detslam {
namespace {

using synth::KinectDepthModel;

// A model with every random effect and every dropout off: only the disparity steps remain.
KinectDepthModel QuietModel() {
  KinectDepthModel m;
  m.sigma_white = m.sigma_correlated = m.bias_amplitude = 0;
  m.border_left = m.border_right = m.border_top = m.border_bottom = 0;
  m.edge_dropout = m.edge_mixed = 0;
  m.grazing_cos_lo = -2;
  m.grazing_cos_hi = -1;  // never grazing
  m.dark_lo = -2;
  m.dark_hi = -1;  // never dark
  m.hole_fraction = 1e-12;
  m.speckle_dropout = 0;
  return m;
}

cv::Mat Bright(int w = 640, int h = 480) { return cv::Mat(h, w, CV_8U, cv::Scalar(200)); }

TEST(KinectDepthTest, DepthComesInEighthPixelDisparitySteps) {
  const PinholeCamera cam = SynthCamera();
  const KinectDepthModel m = QuietModel();
  const double fb = cam.fx * m.baseline;
  for (const float z : {0.8f, 1.7f, 3.3f, 5.2f}) {
    const cv::Mat depth(480, 640, CV_32F, cv::Scalar(z));
    const cv::Mat d16 = synth::MakeKinectDepth16(depth, Bright(), cam, m, 1, 2, 3);
    const double written = d16.at<uint16_t>(240, 320) / cam.depth_map_factor;
    // The nearest 1/8-pixel disparity step, then the 0.2 mm depth PNG step.
    const double expected = fb / (std::round(fb / z / 0.125) * 0.125);
    EXPECT_NEAR(written, expected, 0.5 / cam.depth_map_factor + 1e-9) << "z " << z;
    // The step between neighbouring disparities grows with z^2 (about 3 cm at 3.3 m).
    const double step = z * z / fb * 0.125;
    EXPECT_LE(std::abs(written - z), 0.5 * step + 1e-3) << "z " << z;
    EXPECT_EQ(cv::countNonZero(d16 != d16.at<uint16_t>(240, 320)), 0);
  }
}

TEST(KinectDepthTest, NoiseIsCorrelatedTheDistortionIsFixedAndRangeLimitsHold) {
  const PinholeCamera cam = SynthCamera();
  KinectDepthModel m = QuietModel();
  m.sigma_white = 0.02;
  m.sigma_correlated = 0.08;
  m.bias_amplitude = 0.06;
  const cv::Mat depth(480, 640, CV_32F, cv::Scalar(2.5f));
  const cv::Mat a = synth::MakeKinectDepth16(depth, Bright(), cam, m, 7, 1, 10);
  const cv::Mat a2 = synth::MakeKinectDepth16(depth, Bright(), cam, m, 7, 1, 10);
  EXPECT_EQ(cv::countNonZero(a != a2), 0) << "deterministic";
  const cv::Mat b = synth::MakeKinectDepth16(depth, Bright(), cam, m, 7, 1, 11);
  EXPECT_GT(cv::countNonZero(a != b), 1000) << "noise changes per frame";
  // Error statistics: centred, a few centimetres at 2.5 m (Kinect v1: about 1-2 % of depth).
  cv::Mat za;
  a.convertTo(za, CV_64F, 1.0 / cam.depth_map_factor);
  cv::Scalar mean, sd;
  cv::meanStdDev(za - 2.5, mean, sd);
  EXPECT_LT(std::abs(mean[0]), 0.01);
  EXPECT_GT(sd[0], 0.01);
  EXPECT_LT(sd[0], 0.05);
  // Correlated: neighbouring pixels' errors agree far more than independent noise would.
  double same = 0, n = 0;
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u + 1 < 640; ++u) {
      same += a.at<uint16_t>(v, u) == a.at<uint16_t>(v, u + 1);
      ++n;
    }
  }
  EXPECT_GT(same / n, 0.6);
  // The device's distortion is the same in every frame: averaged over frames the error map keeps
  // a spatial pattern (left and right halves differ), which per-frame noise alone would not.
  KinectDepthModel bias_only = QuietModel();
  bias_only.bias_amplitude = 0.2;
  const cv::Mat p1 = synth::MakeKinectDepth16(depth, Bright(), cam, bias_only, 7, 1, 1);
  const cv::Mat p2 = synth::MakeKinectDepth16(depth, Bright(), cam, bias_only, 7, 2, 99);
  EXPECT_EQ(cv::countNonZero(p1 != p2), 0) << "same device, other sequence and frame";
  const cv::Mat p3 = synth::MakeKinectDepth16(depth, Bright(), cam, bias_only, 8, 1, 1);
  EXPECT_GT(cv::countNonZero(p1 != p3), 10000) << "another device";
  // Range: nearer than min_depth or farther than max_depth is missing.
  const cv::Mat near(480, 640, CV_32F, cv::Scalar(0.3f)), far(480, 640, CV_32F, cv::Scalar(9.f));
  EXPECT_EQ(cv::countNonZero(synth::MakeKinectDepth16(near, Bright(), cam, m, 1, 1, 1)), 0);
  EXPECT_EQ(cv::countNonZero(synth::MakeKinectDepth16(far, Bright(), cam, m, 1, 1, 1)), 0);
}

TEST(KinectDepthTest, ProjectorShadowLiesLeftOfANearerObjectWithTheParallaxWidth) {
  const PinholeCamera cam = SynthCamera();
  cv::Mat depth(480, 640, CV_32F, cv::Scalar(3.0f));
  depth(cv::Rect(300, 100, 80, 200)).setTo(1.0f);  // a post 1 m away in front of a 3 m wall
  const double fb = cam.fx * 0.075;
  const cv::Mat shadow = synth::ProjectorShadow(depth, cam.fx, 0.075, 0.3);
  const int width = static_cast<int>(std::floor(fb * (1.0 / 1.0 - 1.0 / 3.0)));  // 26 px
  const int row = 200;
  int left = 0;
  for (int u = 0; u < 300; ++u) left += shadow.at<uchar>(row, u) != 0;
  EXPECT_NEAR(left, width, 1);
  for (int u = 300 - width + 1; u < 300; ++u) EXPECT_NE(shadow.at<uchar>(row, u), 0) << u;
  for (int u = 300; u < 640; ++u) EXPECT_EQ(shadow.at<uchar>(row, u), 0) << u;
  EXPECT_EQ(cv::countNonZero(shadow.row(50)), 0);  // rows without the post
  // The depth image has no depth there.
  KinectDepthModel m = QuietModel();
  const cv::Mat d16 = synth::MakeKinectDepth16(depth, Bright(), cam, m, 1, 1, 1);
  EXPECT_EQ(d16.at<uint16_t>(row, 290), 0);
  EXPECT_GT(d16.at<uint16_t>(row, 390), 0);
}

TEST(KinectDepthTest, BordersDarkAndGrazingSurfacesAndEdgesLoseDepth) {
  const PinholeCamera cam = SynthCamera();
  const KinectDepthModel full;  // the realistic defaults
  KinectDepthModel m = QuietModel();
  m.border_left = full.border_left;
  m.border_right = full.border_right;
  m.border_top = full.border_top;
  m.border_bottom = full.border_bottom;
  const cv::Mat wall(480, 640, CV_32F, cv::Scalar(2.0f));
  cv::Mat d16 = synth::MakeKinectDepth16(wall, Bright(), cam, m, 1, 1, 1);
  EXPECT_EQ(cv::countNonZero(d16.colRange(0, m.border_left)), 0);
  EXPECT_EQ(cv::countNonZero(d16.colRange(640 - m.border_right, 640)), 0);
  EXPECT_EQ(cv::countNonZero(d16.rowRange(0, m.border_top)), 0);
  EXPECT_EQ(cv::countNonZero(d16.rowRange(480 - m.border_bottom, 480)), 0);
  const int inner = (640 - m.border_left - m.border_right) * (480 - m.border_top - m.border_bottom);
  EXPECT_EQ(cv::countNonZero(d16), inner);

  // A dark (or glass, infrared 0) half returns nothing; the bright half keeps its depth.
  m = QuietModel();
  m.dark_lo = full.dark_lo;
  m.dark_hi = full.dark_hi;
  cv::Mat ir = Bright();
  ir.colRange(0, 320).setTo(0);
  d16 = synth::MakeKinectDepth16(wall, ir, cam, m, 1, 1, 1);
  EXPECT_EQ(cv::countNonZero(d16.colRange(0, 320)), 0);
  EXPECT_EQ(cv::countNonZero(d16.colRange(320, 640)), 320 * 480);

  // A floor seen nearly edge-on loses most depth; the same floor seen steeply keeps it.
  m = QuietModel();
  m.grazing_cos_lo = full.grazing_cos_lo;
  m.grazing_cos_hi = full.grazing_cos_hi;
  auto plane = [&](double tilt_deg) {
    // Plane through (0, 0, 2) with normal tilted from the optical axis by `tilt_deg` about x.
    const double t = tilt_deg * M_PI / 180.0;
    const cv::Vec3d n(0, std::sin(t), -std::cos(t));
    cv::Mat depth(480, 640, CV_32F);
    for (int v = 0; v < 480; ++v) {
      for (int u = 0; u < 640; ++u) {
        const cv::Vec3d ray((u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy, 1.0);
        const double s = n.dot(cv::Vec3d(0, 0, 2)) / n.dot(ray);
        depth.at<float>(v, u) = s > 0 ? static_cast<float>(s) : 0.f;
      }
    }
    return depth;
  };
  const cv::Mat steep = synth::MakeKinectDepth16(plane(20), Bright(), cam, m, 1, 1, 1);
  const cv::Mat grazing = synth::MakeKinectDepth16(plane(84), Bright(), cam, m, 1, 1, 1);
  const cv::Rect centre(280, 200, 80, 80);
  EXPECT_EQ(cv::countNonZero(steep(centre)), centre.area());
  EXPECT_LT(cv::countNonZero(grazing(centre)), centre.area() / 5);

  // At a depth edge a pixel is missing, a mixed pixel between the surfaces, or kept.
  m = QuietModel();
  m.edge_dropout = full.edge_dropout;
  m.edge_mixed = full.edge_mixed;
  // The nearer surface on the left: the projector's shadow falls left of it, off this edge.
  cv::Mat step(480, 640, CV_32F, cv::Scalar(1.5f));
  step.colRange(320, 640).setTo(3.0f);
  d16 = synth::MakeKinectDepth16(step, Bright(), cam, m, 1, 1, 1);
  int missing = 0, mixed = 0;
  for (int v = 0; v < 480; ++v) {
    for (int u : {319, 320}) {
      const double z = d16.at<uint16_t>(v, u) / cam.depth_map_factor;
      if (z == 0) ++missing;
      else if (z > 1.6 && z < 2.9) ++mixed;
    }
  }
  EXPECT_NEAR(missing / 960.0, full.edge_dropout, 0.07);
  EXPECT_NEAR(mixed / 960.0, full.edge_mixed, 0.07);
  EXPECT_EQ(cv::countNonZero(d16.colRange(0, 318) == 0), 0);  // away from the edge: all kept
  EXPECT_EQ(cv::countNonZero(d16.colRange(322, 640) == 0), 0);
}

TEST(ColourCameraTest, ExposureDriftsWithinItsBoundsAndNoiseGrowsWithBrightness) {
  const synth::ColourCameraModel m;
  double lo = 10, hi = 0;
  for (int i = 0; i < 3000; ++i) {
    const double g = synth::ExposureGain(m, 5, i / 30.0);
    lo = std::min(lo, g);
    hi = std::max(hi, g);
  }
  EXPECT_GE(lo, 1 - m.exposure_drift - 1e-12);
  EXPECT_LE(hi, 1 + m.exposure_drift + 1e-12);
  EXPECT_GT(hi - lo, m.exposure_drift);  // it does drift
  EXPECT_NEAR(synth::ExposureGain(m, 5, 1.0), synth::ExposureGain(m, 5, 1.0 + 1.0 / 30), 0.02);

  synth::ColourCameraModel plain = m;
  plain.psf_sigma = 0;
  cv::Mat dark(200, 200, CV_8UC3, cv::Scalar::all(20)), bright(200, 200, CV_8UC3, cv::Scalar::all(200));
  synth::ApplyColourCamera(&dark, plain, 1.0, 3, 4);
  synth::ApplyColourCamera(&bright, plain, 1.0, 3, 4);
  cv::Scalar md, sd_dark, mb, sd_bright;
  cv::meanStdDev(dark, md, sd_dark);
  cv::meanStdDev(bright, mb, sd_bright);
  EXPECT_NEAR(md[0], 20, 0.5);
  EXPECT_NEAR(mb[0], 200, 0.5);
  EXPECT_GT(sd_bright[0], 1.5 * sd_dark[0]);  // photon noise
  // Gain brightens; the point spread softens a sharp edge.
  cv::Mat edge(100, 100, CV_8UC3, cv::Scalar::all(50));
  edge.colRange(50, 100).setTo(cv::Scalar::all(150));
  synth::ColourCameraModel soft = m;
  soft.read_sigma = soft.shot_gain = 0;
  cv::Mat e = edge.clone();
  synth::ApplyColourCamera(&e, soft, 1.0, 1, 1);
  EXPECT_GT(e.at<cv::Vec3b>(50, 49)[0], 55);
  EXPECT_LT(e.at<cv::Vec3b>(50, 50)[0], 145);
  cv::Mat g = edge.clone();
  synth::ApplyColourCamera(&g, soft, 1.1, 1, 1);
  EXPECT_NEAR(g.at<cv::Vec3b>(50, 10)[0], 55, 1);
}

TEST(RendererTest, RowBandsFromOnePoseEqualTheWholeFrame) {
  const synth::Scene scene = synth::BuildOfficeScene(4);
  const PinholeCamera cam = SynthCamera();
  const Rigid3d pose(Eigen::Quaterniond(Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitX())),
                 Eigen::Vector3d(0.1, -1.0, 1.4));
  const synth::IdealFrame whole = synth::RenderIdeal(scene, {}, {}, cam, pose);
  synth::IdealFrame bands{cv::Mat(480, 640, CV_8UC3), cv::Mat(480, 640, CV_32F),
                          cv::Mat(480, 640, CV_16U), cv::Mat(480, 640, CV_8U)};
  for (int v = 0; v < 480; v += 37)
    synth::RenderIdealRows(scene, {}, {}, cam, pose, v, std::min(480, v + 37), &bands);
  EXPECT_EQ(cv::norm(whole.bgr, bands.bgr, cv::NORM_INF), 0);
  EXPECT_EQ(cv::norm(whole.depth, bands.depth, cv::NORM_INF), 0);
  EXPECT_EQ(cv::norm(whole.ir, bands.ir, cv::NORM_INF), 0);
  EXPECT_GT(cv::countNonZero(whole.depth), 640 * 470);
}

TEST(SynthRealismTest, RealisticFramesAreDeterministicWithDepthAtItsOwnTime) {
  SynthOptions o;
  o.preset = "walking_xyz";
  o.seed = 3;
  o.frames = 40;
  o.realism = SynthRealism::kRealistic;
  const SyntheticSequence seq(o), again(o);
  SynthOptions easy_options = o;
  easy_options.realism = SynthRealism::kEasy;
  const SyntheticSequence easy(easy_options);
  double max_offset_ms = 0;
  for (int k = 0; k < 40; ++k) {
    const double offset_ms = (seq.DepthStampOf(k).ns - seq.StampOf(k).ns) * 1e-6;
    EXPECT_GE(offset_ms, 2.0);
    EXPECT_LE(offset_ms, 17.0);
    max_offset_ms = std::max(max_offset_ms, offset_ms);
  }
  EXPECT_GT(max_offset_ms, 10.0);  // later than the easy mode's 9 ms at most
  const SynthFrame a = seq.Render(20), b = again.Render(20), e = easy.Render(20);
  EXPECT_EQ(cv::norm(a.bgr, b.bgr, cv::NORM_INF), 0);
  EXPECT_EQ(cv::norm(a.depth16, b.depth16, cv::NORM_INF), 0);
  EXPECT_EQ(a.world_from_cam.translation(), e.world_from_cam.translation());
  // Much more depth is missing than in the easy mode.
  const double missing = 1.0 - cv::countNonZero(a.depth16) / static_cast<double>(a.depth16.total());
  const double missing_easy =
      1.0 - cv::countNonZero(e.depth16) / static_cast<double>(e.depth16.total());
  EXPECT_GT(missing, 0.15);
  EXPECT_LT(missing_easy, 0.08);
}

}  // namespace
}  // namespace detslam
