#include "detslam/dynamic/detslam_stage.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

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

}  // namespace
}  // namespace detslam
