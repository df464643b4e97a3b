#include "detslam/dynamic/dynamic_filter.h"

#include <gtest/gtest.h>

#include <algorithm>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "detslam/core/check.h"
#include "detslam/core/rng.h"

namespace detslam {
namespace {

// The hand-made scene below is laid out for a 5 px mask dilation (the arm sits 8 px from the mask).
DynamicFilterOptions SceneOptions() {
  DynamicFilterOptions o;
  o.mask_dilation_px = 5;
  return o;
}

// A 160x120 depth image: a wall at 4 m; a person (x in [60, 90), y in [30, 110)) whose depth rises
// from 1.9 m (left) to 2.1 m (right); an arm the mask misses (x in [90, 100), y in [50, 56)) at
// 2.0 m; a chair outside the person's box at 2.0 m; a depth hole at (100, 70).
// The mask covers the body plus leaked wall pixels: x in [90, 92) for y in [80, 100), and y in
// [28, 30) for x in [60, 90). The box is x in [55, 105), y in [25, 115).
struct PersonScene {
  cv::Mat depth = cv::Mat(120, 160, CV_32FC1, cv::Scalar(4.0f));
  cv::Mat mask = cv::Mat::zeros(120, 160, CV_8UC1);
  cv::Rect box{55, 25, 50, 90};

  PersonScene() {
    for (int y = 30; y < 110; ++y) {
      for (int x = 60; x < 90; ++x) depth.at<float>(y, x) = PersonDepth(x);
    }
    depth(cv::Rect(90, 50, 10, 6)).setTo(2.0f);    // arm
    depth(cv::Rect(125, 55, 10, 10)).setTo(2.0f);  // chair, outside the box
    depth.at<float>(70, 100) = 0.0f;               // hole
    mask(cv::Rect(60, 30, 30, 80)).setTo(255);     // body
    mask(cv::Rect(90, 80, 2, 20)).setTo(255);      // leaked wall pixels
    mask(cv::Rect(60, 28, 30, 2)).setTo(255);      // leaked wall pixels
  }
  static float PersonDepth(int x) { return 1.9f + 0.2f * static_cast<float>(x - 60) / 29.0f; }

  Instance Person(float score = 0.9f) const {
    Instance instance;
    instance.class_id = 0;
    instance.class_name = "person";
    instance.score = score;
    instance.box = box;
    instance.mask = mask;
    return instance;
  }
};

float DepthAt(const cv::Mat& depth, const cv::Point2f& pt) {
  const int u = static_cast<int>(std::lround(pt.x));
  const int v = static_cast<int>(std::lround(pt.y));
  if (depth.empty() || u < 0 || v < 0 || u >= depth.cols || v >= depth.rows) return -1.0f;
  const float d = depth.at<float>(v, u);
  return d > 0.0f ? d : -1.0f;
}

struct Labelled {
  std::vector<KeypointLabel> labels;
  DynamicFilterStats stats;
};

Labelled Label(const std::vector<cv::Point2f>& points, const std::vector<Instance>& instances,
               const cv::Mat& depth, const DynamicFilterOptions& options) {
  std::vector<cv::KeyPoint> keypoints;
  std::vector<float> keypoint_depth;
  for (const cv::Point2f& p : points) {
    keypoints.emplace_back(p, 7.0f);
    keypoint_depth.push_back(DepthAt(depth, p));
  }
  Labelled out;
  out.labels.assign(points.size(), KeypointLabel::kStatic);
  out.stats =
      LabelDynamicKeypoints(keypoints, keypoint_depth, instances, depth, options, &out.labels);
  return out;
}

TEST(DominantDepthModeTest, ContiguousRunAroundTheMostPopulatedBin) {
  // Bins of 0.05 m: 2.01, 2.03 -> 40; 2.06, 2.07 -> 41; 2.12 -> 42; 2.60 -> 52; 4.01, 4.02 -> 80.
  const std::vector<float> depths = {2.01f, 2.03f, 2.06f, 2.07f, 2.12f, 2.60f,
                                     4.01f, 4.02f, 0.0f,  -1.0f, NAN};
  const DepthRange range = DominantDepthMode(depths, 0.05, 0.5, 0.0);
  ASSERT_TRUE(range.valid);
  EXPECT_FLOAT_EQ(range.min, 2.01f);
  EXPECT_FLOAT_EQ(range.max, 2.12f);
}

TEST(DominantDepthModeTest, WindowCapsTheRun) {
  // Tie between bins 40 and 41 goes to the nearer one (centre 2.025); window +-0.05 keeps
  // [1.975, 2.075].
  const std::vector<float> depths = {2.01f, 2.03f, 2.06f, 2.07f, 2.12f};
  const DepthRange range = DominantDepthMode(depths, 0.05, 0.05, 0.0);
  ASSERT_TRUE(range.valid);
  EXPECT_FLOAT_EQ(range.min, 2.01f);
  EXPECT_FLOAT_EQ(range.max, 2.07f);
}

TEST(DominantDepthModeTest, SparseBinsEndTheRun) {
  std::vector<float> depths(100, 2.01f);   // bin 40: 100
  depths.push_back(2.06f);                 // bin 41: 1 (< 2% of 100)
  depths.insert(depths.end(), 50, 2.11f);  // bin 42: 50
  const DepthRange sparse_ends = DominantDepthMode(depths, 0.05, 0.5, 0.02);
  ASSERT_TRUE(sparse_ends.valid);
  EXPECT_FLOAT_EQ(sparse_ends.max, 2.01f);
  const DepthRange any_pixel_counts = DominantDepthMode(depths, 0.05, 0.5, 0.0);
  EXPECT_FLOAT_EQ(any_pixel_counts.max, 2.11f);
}

TEST(DominantDepthModeTest, NoValidDepth) {
  EXPECT_FALSE(DominantDepthMode({}, 0.05, 0.5, 0.02).valid);
  EXPECT_FALSE(DominantDepthMode({0.0f, -2.0f, INFINITY}, 0.05, 0.5, 0.02).valid);
}

TEST(ObjectDepthIntervalTest, DominantModeIgnoresLeakedWallPixels) {
  const PersonScene scene;
  const DynamicFilterOptions options;
  const DepthInterval interval = ObjectDepthInterval(scene.depth, scene.mask, scene.box, options);
  ASSERT_TRUE(interval.valid);
  EXPECT_NEAR(interval.m_obj, 1.9, 1e-5);
  EXPECT_NEAR(interval.M_obj, 2.1, 1e-5);
  EXPECT_NEAR(interval.d_roi, 4.0 - 1.9, 1e-5);  // the box holds the wall and the person
  EXPECT_NEAR(interval.lo, 1.9 - 0.1 * 2.1, 1e-5);
  EXPECT_NEAR(interval.hi, 2.1 + 0.1 * 2.1, 1e-5);
}

TEST(ObjectDepthIntervalTest, RawMinMaxTakesTheLeakedWallPixelsAsThePaperWritesIt) {
  const PersonScene scene;
  DynamicFilterOptions options;
  options.dominant_mode = false;
  const DepthInterval interval = ObjectDepthInterval(scene.depth, scene.mask, scene.box, options);
  ASSERT_TRUE(interval.valid);
  double lo = 1e9, hi = -1e9;  // every mask pixel with depth, wall included
  for (int y = scene.box.y; y < scene.box.y + scene.box.height; ++y) {
    for (int x = scene.box.x; x < scene.box.x + scene.box.width; ++x) {
      const float d = scene.depth.at<float>(y, x);
      if (scene.mask.at<uint8_t>(y, x) == 0 || !(d > 0)) continue;
      lo = std::min<double>(lo, d);
      hi = std::max<double>(hi, d);
    }
  }
  EXPECT_NEAR(interval.m_obj, lo, 1e-6);
  EXPECT_NEAR(interval.M_obj, hi, 1e-6);
  EXPECT_GT(interval.M_obj, 3.0);  // the leaked wall pixels reach the wall's depth
  EXPECT_NEAR(interval.hi, hi + 0.1 * interval.d_roi, 1e-6);
}

// A 10x10 image at 3.55 m with one pixel at 1.55 m; the object's three mask pixels at 2.05, 2.15
// and 2.25 m (one 0.5 m bin). d = 3.55 - 1.55 = 2.0.
struct AlphaScene {
  cv::Mat depth = cv::Mat(10, 10, CV_32FC1, cv::Scalar(3.55f));
  cv::Mat mask = cv::Mat::zeros(10, 10, CV_8UC1);
  cv::Rect box{0, 0, 10, 10};
  AlphaScene() {
    depth.at<float>(9, 9) = 1.55f;
    depth.at<float>(2, 2) = 2.05f;
    depth.at<float>(2, 3) = 2.15f;
    depth.at<float>(2, 4) = 2.25f;
    mask(cv::Rect(2, 2, 3, 1)).setTo(255);
  }
  DynamicFilterOptions Options(double alpha) const {
    DynamicFilterOptions options;
    options.alpha = alpha;
    options.depth_bin_m = 0.5;
    options.mask_dilation_px = 0;
    return options;
  }
};

TEST(ObjectDepthIntervalTest, AlphaWidensByAlphaTimesBoxSpan) {
  const AlphaScene scene;
  for (double alpha : {0.0, 0.1, 0.25}) {
    const DepthInterval interval =
        ObjectDepthInterval(scene.depth, scene.mask, scene.box, scene.Options(alpha));
    ASSERT_TRUE(interval.valid);
    EXPECT_NEAR(interval.m_obj, 2.05, 1e-6);
    EXPECT_NEAR(interval.M_obj, 2.25, 1e-6);
    EXPECT_NEAR(interval.d_roi, 2.0, 1e-6);
    EXPECT_NEAR(interval.lo, 2.05 - alpha * 2.0, 1e-6) << alpha;
    EXPECT_NEAR(interval.hi, 2.25 + alpha * 2.0, 1e-6) << alpha;
  }
}

TEST(ObjectDepthIntervalTest, EmptyMaskUsesTheBoxAndNoDepthIsInvalid) {
  const AlphaScene scene;
  // Box-only over the 3.55 m background: m_obj = M_obj = 3.55, d = 0 (box avoids (9, 9)).
  const DepthInterval box_only =
      ObjectDepthInterval(scene.depth, cv::Mat(), cv::Rect(5, 5, 3, 3), scene.Options(0.1));
  ASSERT_TRUE(box_only.valid);
  EXPECT_NEAR(box_only.m_obj, 3.55, 1e-6);
  EXPECT_NEAR(box_only.hi, 3.55, 1e-6);
  const cv::Mat no_depth = cv::Mat::zeros(10, 10, CV_32FC1);
  EXPECT_FALSE(ObjectDepthInterval(no_depth, scene.mask, scene.box, scene.Options(0.1)).valid);
  EXPECT_FALSE(ObjectDepthInterval(cv::Mat(), scene.mask, scene.box, scene.Options(0.1)).valid);
}

TEST(LabelDynamicKeypointsTest, AlphaDecidesAtTheIntervalEdges) {
  const AlphaScene scene;
  Instance instance;
  instance.class_name = "person";
  instance.score = 1.0f;
  instance.box = scene.box;
  instance.mask = scene.mask;
  // Keypoints outside the mask, with hand-set depths.
  const std::vector<float> probe = {1.84f, 1.86f, 2.04f, 2.06f, 2.44f, 2.46f, 1.54f, 2.76f};
  std::vector<cv::KeyPoint> keypoints;
  for (size_t i = 0; i < probe.size(); ++i) keypoints.emplace_back(cv::Point2f(7.0f, 6.0f), 7.0f);
  auto label = [&](double alpha) {
    std::vector<KeypointLabel> labels(probe.size(), KeypointLabel::kStatic);
    LabelDynamicKeypoints(keypoints, probe, {instance}, scene.depth, scene.Options(alpha), &labels);
    return labels;
  };
  constexpr auto S = KeypointLabel::kStatic;
  constexpr auto D = KeypointLabel::kDynamicDepth;
  // alpha 0: [2.05, 2.25]; 0.1: [1.85, 2.45]; 0.25: [1.55, 2.75].
  EXPECT_EQ(label(0.0), (std::vector<KeypointLabel>{S, S, S, D, S, S, S, S}));
  EXPECT_EQ(label(0.1), (std::vector<KeypointLabel>{S, D, D, D, D, S, S, S}));
  EXPECT_EQ(label(0.25), (std::vector<KeypointLabel>{D, D, D, D, D, D, S, S}));
}

TEST(LabelDynamicKeypointsTest, PersonInFrontOfWall) {
  const PersonScene scene;
  const std::vector<cv::Point2f> points = {
      {70, 60},      // 0 person, in the mask
      {85.4f, 100},  // 1 person, in the mask
      {91, 90},      // 2 leaked wall pixel, in the mask
      {97, 53},      // 3 arm the mask missed (8 px from the mask), person depth
      {102, 100},    // 4 wall in the box
      {102, 30},     // 5 wall in the box
      {100, 70},     // 6 depth hole in the box, outside the mask
      {20, 20},      // 7 wall outside the box
      {130, 60},     // 8 chair at person depth outside the box
      {-3, 500},     // 9 outside the image
  };
  const Labelled out = Label(points, {scene.Person()}, scene.depth, SceneOptions());
  constexpr auto S = KeypointLabel::kStatic;
  constexpr auto M = KeypointLabel::kDynamicMask;
  constexpr auto D = KeypointLabel::kDynamicDepth;
  EXPECT_EQ(out.labels, (std::vector<KeypointLabel>{M, M, M, D, S, S, S, S, S, S}));
  EXPECT_EQ(out.stats.instances_used, 1);
  EXPECT_EQ(out.stats.rejected_mask, 3);
  EXPECT_EQ(out.stats.rejected_depth, 1);

  DynamicFilterOptions no_depth_step = SceneOptions();
  no_depth_step.depth_step = false;
  const Labelled mask_only = Label(points, {scene.Person()}, scene.depth, no_depth_step);
  EXPECT_EQ(mask_only.labels, (std::vector<KeypointLabel>{M, M, M, S, S, S, S, S, S, S}));
  const Labelled no_depth_image = Label(points, {scene.Person()}, cv::Mat(), SceneOptions());
  EXPECT_EQ(no_depth_image.labels, mask_only.labels);
}

TEST(LabelDynamicKeypointsTest, NonDynamicClassesAreIgnored) {
  const PersonScene scene;
  Instance chair = scene.Person();
  chair.class_id = 56;
  chair.class_name = "chair";
  const std::vector<cv::Point2f> points = {{70, 60}, {97, 53}};
  const Labelled ignored = Label(points, {chair}, scene.depth, SceneOptions());
  EXPECT_EQ(ignored.labels, std::vector<KeypointLabel>(2, KeypointLabel::kStatic));
  EXPECT_EQ(ignored.stats.instances_used, 0);

  DynamicFilterOptions with_chairs = SceneOptions();
  with_chairs.dynamic_classes = {"person", "chair"};
  const Labelled used = Label(points, {chair}, scene.depth, with_chairs);
  EXPECT_EQ(used.labels, (std::vector<KeypointLabel>{KeypointLabel::kDynamicMask,
                                                     KeypointLabel::kDynamicDepth}));
  EXPECT_EQ(used.stats.instances_used, 1);
}

TEST(LabelDynamicKeypointsTest, MinScore) {
  const PersonScene scene;
  DynamicFilterOptions options;
  options.min_score = 0.5f;
  const std::vector<cv::Point2f> points = {{70, 60}};
  EXPECT_EQ(Label(points, {scene.Person(0.4f)}, scene.depth, options).labels[0],
            KeypointLabel::kStatic);
  EXPECT_EQ(Label(points, {scene.Person(0.6f)}, scene.depth, options).labels[0],
            KeypointLabel::kDynamicMask);
}

TEST(LabelDynamicKeypointsTest, DilationCatchesKeypointsNearTheMask) {
  const PersonScene scene;
  // The body mask ends at x = 89 and starts at x = 60; rows 30..109 (rows 28..29 leaked).
  const std::vector<cv::Point2f> points = {{92, 60}, {57, 60}, {75, 112}, {92, 112}, {96, 60}};
  DynamicFilterOptions options;
  options.depth_step = false;
  options.mask_dilation_px = 5;
  constexpr auto S = KeypointLabel::kStatic;
  constexpr auto M = KeypointLabel::kDynamicMask;
  // (92, 112) is 3 px from the corner (89, 109) on both axes: 4.2 px, inside a radius-5 ellipse.
  EXPECT_EQ(Label(points, {scene.Person()}, scene.depth, options).labels,
            (std::vector<KeypointLabel>{M, M, M, M, S}));
  options.mask_dilation_px = 0;
  EXPECT_EQ(Label(points, {scene.Person()}, scene.depth, options).labels,
            (std::vector<KeypointLabel>(5, S)));
}

TEST(LabelDynamicKeypointsTest, BoxOnlyInstanceUsesTheBoxAsMask) {
  const PersonScene scene;
  Instance box_only = scene.Person();
  box_only.mask = cv::Mat();
  DynamicFilterOptions options;
  options.mask_dilation_px = 0;
  const std::vector<cv::Point2f> points = {{102, 100}, {54, 60}, {130, 60}};
  // Without a depth image the image size comes from the boxes.
  const Labelled out = Label(points, {box_only}, cv::Mat(), options);
  EXPECT_EQ(out.labels,
            (std::vector<KeypointLabel>{KeypointLabel::kDynamicMask, KeypointLabel::kStatic,
                                        KeypointLabel::kStatic}));
}

TEST(LabelDynamicKeypointsTest, KeepsExistingLabelsAndRejectsBadInput) {
  const PersonScene scene;
  std::vector<cv::KeyPoint> keypoints = {cv::KeyPoint(cv::Point2f(20, 20), 7.0f)};
  std::vector<KeypointLabel> labels = {KeypointLabel::kGeometric};
  LabelDynamicKeypoints(keypoints, {4.0f}, {scene.Person()}, scene.depth, DynamicFilterOptions(),
                        &labels);
  EXPECT_EQ(labels[0], KeypointLabel::kGeometric);

  Instance bad = scene.Person();
  bad.mask = cv::Mat::zeros(10, 10, CV_8UC1);
  labels = {KeypointLabel::kStatic};
  EXPECT_THROW(
      LabelDynamicKeypoints(keypoints, {4.0f}, {bad}, scene.depth, DynamicFilterOptions(), &labels),
      InputError);
  EXPECT_THROW(
      DynamicIgnoreMask({scene.Person()}, scene.depth, cv::Size(10, 10), DynamicFilterOptions()),
      InputError);
}

TEST(DynamicFilterOptionsTest, Check) {
  std::string error;
  EXPECT_TRUE(DynamicFilterOptions().Check(&error)) << error;
  DynamicFilterOptions options;
  options.alpha = -0.1;
  EXPECT_FALSE(options.Check(&error));
  EXPECT_NE(error.find("alpha"), std::string::npos);
  options = DynamicFilterOptions();
  options.depth_bin_m = 0.0;
  EXPECT_FALSE(options.Check(&error));
  options = DynamicFilterOptions();
  options.mask_dilation_px = -1;
  EXPECT_FALSE(options.Check(&error));
  options = DynamicFilterOptions();
  options.mode_window_m = 0.01;  // less than half a bin
  EXPECT_FALSE(options.Check(&error));
  options = DynamicFilterOptions();
  options.min_score = 1.5f;
  EXPECT_FALSE(options.Check(&error));
}

TEST(DynamicIgnoreMaskTest, PersonScenePixels) {
  const PersonScene scene;
  const cv::Mat ignore =
      DynamicIgnoreMask({scene.Person()}, scene.depth, scene.depth.size(), SceneOptions());
  ASSERT_EQ(ignore.type(), CV_8UC1);
  ASSERT_EQ(ignore.size(), scene.depth.size());
  EXPECT_NE(ignore.at<uint8_t>(53, 97), 0);    // arm
  EXPECT_EQ(ignore.at<uint8_t>(100, 102), 0);  // wall in the box
  EXPECT_EQ(ignore.at<uint8_t>(60, 130), 0);   // chair outside the box
  // The arm's 10x6 pixels beyond the dilated mask are all rejected: count the box's rejections.
  const int in_box = cv::countNonZero(ignore(scene.box));
  const int outside_box = cv::countNonZero(ignore) - in_box;
  EXPECT_GT(in_box, 30 * 80 + 60);
  EXPECT_GT(outside_box, 0);  // dilation reaches beyond the box below the body
}

TEST(DynamicIgnoreMaskTest, AgreesWithLabelDynamicKeypoints) {
  const PersonScene scene;
  Rng rng(7);
  for (int trial = 0; trial < 20; ++trial) {
    Instance box_only;
    box_only.class_name = "person";
    box_only.score = 0.8f;
    box_only.box = cv::Rect(rng.UniformInt(-20, 150), rng.UniformInt(-20, 110),
                            rng.UniformInt(1, 60), rng.UniformInt(1, 60));
    Instance chair = scene.Person();
    chair.class_name = "chair";
    chair.box = cv::Rect(110, 40, 40, 40);
    chair.mask = cv::Mat::zeros(scene.depth.size(), CV_8UC1);
    chair.mask(cv::Rect(125, 55, 10, 10)).setTo(255);
    DynamicFilterOptions options;
    options.alpha = rng.Uniform(0.0, 0.5);
    options.mask_dilation_px = rng.UniformInt(0, 8);
    options.depth_step = trial % 5 != 4;
    if (trial % 3 == 0) options.dynamic_classes.push_back("chair");
    const std::vector<Instance> instances = {scene.Person(), box_only, chair};
    const cv::Mat ignore = DynamicIgnoreMask(instances, scene.depth, scene.depth.size(), options);
    std::vector<cv::Point2f> points;
    for (int i = 0; i < 2000; ++i) {
      points.emplace_back(static_cast<float>(rng.Uniform(-5.0, 165.0)),
                          static_cast<float>(rng.Uniform(-5.0, 125.0)));
    }
    const Labelled out = Label(points, instances, scene.depth, options);
    int rejected = 0;
    for (size_t i = 0; i < points.size(); ++i) {
      const int u = static_cast<int>(std::lround(points[i].x));
      const int v = static_cast<int>(std::lround(points[i].y));
      const bool inside = u >= 0 && v >= 0 && u < ignore.cols && v < ignore.rows;
      const bool masked = inside && ignore.at<uint8_t>(v, u) != 0;
      const bool labelled = out.labels[i] != KeypointLabel::kStatic;
      rejected += labelled;
      ASSERT_EQ(masked, labelled) << "trial " << trial << " point " << points[i];
    }
    EXPECT_GT(rejected, 0);
    EXPECT_EQ(rejected, out.stats.rejected_mask + out.stats.rejected_depth);
  }
}

}  // namespace
}  // namespace detslam
