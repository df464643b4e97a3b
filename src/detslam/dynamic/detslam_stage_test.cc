#include "detslam/dynamic/detslam_stage.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "detslam/features/orb_extractor.h"
#include "detslam/features/texture_for_test.h"

namespace detslam {
namespace {

// Returns the same instances on every frame.
class FixedSegmenter : public Segmenter {
 public:
  explicit FixedSegmenter(std::vector<Instance> instances) : instances_(std::move(instances)) {}
  std::vector<Instance> Segment(const SegmenterInput&) override { return instances_; }
  std::string name() const override { return "fixed"; }

 private:
  std::vector<Instance> instances_;
};

Instance Box(const std::string& class_name, float score, cv::Rect box) {
  Instance in;
  in.class_name = class_name;
  in.class_id = class_name == "person" ? 0 : 73;
  in.score = score;
  in.box = box;
  in.mask = cv::Mat::zeros(120, 160, CV_8UC1);
  in.mask(box).setTo(255);
  return in;
}

SegmenterInput Input(int64_t index) {
  SegmenterInput input;
  input.index = index;
  input.bgr = cv::Mat(120, 160, CV_8UC3, cv::Scalar(90, 90, 90));
  input.depth_m = cv::Mat(120, 160, CV_32FC1, cv::Scalar(2.0f));
  return input;
}

std::vector<std::string> Names(const std::vector<Instance>& instances) {
  std::vector<std::string> out;
  for (const Instance& i : instances) out.push_back(i.class_name + "@" + std::to_string(i.box.x));
  return out;
}

TEST(DetSlamStageTest, KeepsOnlyTheInstancesTheFilterUses) {
  // A person, a book (not a dynamic class) and a person scored below Dynamic.MinScore.
  FixedSegmenter segmenter({Box("person", 0.9f, {10, 10, 30, 60}), Box("book", 0.8f, {60, 20, 20, 20}),
                            Box("person", 0.2f, {100, 10, 30, 60})});
  DetSlamOptions options;
  options.filter.min_score = 0.5f;
  DetSlamStage stage(options, &segmenter);
  const cv::Mat gray(120, 160, CV_8UC1, cv::Scalar(90));
  const std::vector<std::string> person = {"person@10"};
  EXPECT_EQ(Names(stage.Segment(Input(0), gray).instances), person);
  // The asynchronous segmentation thread's entry point filters the same way.
  DetSlamStage async_stage(options, &segmenter);
  EXPECT_EQ(Names(async_stage.Detect(Input(0)).instances), person);
  // A book made dynamic is kept.
  options.filter.dynamic_classes = {"person", "book"};
  DetSlamStage with_books(options, &segmenter);
  const std::vector<std::string> both = {"person@10", "book@60"};
  EXPECT_EQ(Names(with_books.Segment(Input(0), gray).instances), both);
}

TEST(DetSlamStageTest, AnUnusedInstanceIsNotRememberedWhenItDisappears) {
  // The memory carries lost instances forward a few frames: a book seen once must not come back.
  class Once : public Segmenter {
   public:
    std::vector<Instance> Segment(const SegmenterInput& in) override {
      std::vector<Instance> out = {Box("person", 0.9f, {10, 10, 30, 60})};
      if (in.index == 0) out.push_back(Box("book", 0.8f, {60, 20, 20, 20}));
      return out;
    }
    std::string name() const override { return "once"; }
  } segmenter;
  DetSlamStage stage(DetSlamOptions{}, &segmenter);
  const cv::Mat gray(120, 160, CV_8UC1, cv::Scalar(90));
  stage.Segment(Input(0), gray);
  const std::vector<std::string> person = {"person@10"};
  EXPECT_EQ(Names(stage.Segment(Input(1), gray).instances), person);
}

TEST(DetSlamStageTest, ExtractionReportsWhereKeypointsWereWithheld) {
  const cv::Mat gray = testing::MakeTexture(320, 240, 7);
  const cv::Mat depth(240, 320, CV_32FC1, cv::Scalar(2.0f));
  Instance person;
  person.class_name = "person";
  person.class_id = 0;
  person.score = 0.9f;
  person.box = {100, 60, 60, 120};
  person.mask = cv::Mat::zeros(240, 320, CV_8UC1);
  person.mask(person.box).setTo(255);
  cv::Mat ignore = cv::Mat::zeros(240, 320, CV_8UC1);
  ignore(cv::Rect(0, 0, 20, 20)).setTo(255);
  const cv::Mat ignore_before = ignore.clone();
  OrbOptions orb;
  orb.num_features = 500;
  const OrbExtractor extractor(orb);
  for (const bool premask : {true, false}) {
    DetSlamOptions options;
    options.premask = premask;
    const DetSlamStage stage(options, nullptr);
    const std::vector<Instance> instances{person};
    const LabelledKeypoints out = stage.Extract(extractor, gray, depth, ignore, &instances);
    ASSERT_EQ(out.withheld.size(), gray.size());
    // The person's (dilated) mask, the depth step over its box and the ignore mask are withheld;
    // far from all of them nothing is.
    EXPECT_NE(out.withheld.at<uint8_t>(120, 130), 0) << premask;
    EXPECT_NE(out.withheld.at<uint8_t>(60 - 5, 130), 0) << premask;  // within the dilation
    EXPECT_NE(out.withheld.at<uint8_t>(5, 5), 0) << premask;
    EXPECT_EQ(out.withheld.at<uint8_t>(200, 290), 0) << premask;
    // Every keypoint labelled dynamic lies where the mask is set, every static one where not.
    for (size_t i = 0; i < out.keypoints.size(); ++i) {
      const cv::Point p(static_cast<int>(std::lround(out.keypoints[i].pt.x)),
                        static_cast<int>(std::lround(out.keypoints[i].pt.y)));
      EXPECT_EQ(out.labels[i] != KeypointLabel::kStatic, out.withheld.at<uint8_t>(p) != 0)
          << premask << " " << p;
    }
    // The caller's ignore mask is not written into.
    EXPECT_EQ(cv::countNonZero(ignore != ignore_before), 0) << premask;
  }
  // Without instances or an ignore mask nothing is withheld.
  const DetSlamStage stage(DetSlamOptions{}, nullptr);
  EXPECT_TRUE(stage.Extract(extractor, gray, depth, cv::Mat(), nullptr).withheld.empty());
}

}  // namespace
}  // namespace detslam
