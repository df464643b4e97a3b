#include "detslam/segmentation/segmenter_factory.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "detslam/core/check.h"
#include "detslam/segmentation/coco_classes.h"
#include "detslam/segmentation/dnn_segmenter.h"
#include "detslam/segmentation/mask_dir.h"

namespace detslam {
namespace {
namespace fs = std::filesystem;

std::string ErrorOf(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(SegmenterFactory, NoneGtMasksAndUnknown) {
  const fs::path dir = fs::temp_directory_path() / "detslam_factory_test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  SegmenterSettings settings;
  EXPECT_EQ(MakeSegmenter("none", dir.string(), settings, "/nonexistent"), nullptr);
  const std::string gt_error = ErrorOf([&] { MakeSegmenter("gt", dir.string(), settings, ""); });
  EXPECT_NE(gt_error.find("synthetic"), std::string::npos) << gt_error;
  EXPECT_NE(gt_error.find((dir / "masks").string()), std::string::npos) << gt_error;
  WriteMasks((dir / "masks").string(), {}, {}, cv::Size(4, 4));
  auto gt = MakeSegmenter("gt", dir.string(), settings, "");
  ASSERT_NE(gt, nullptr);
  EXPECT_EQ(gt->name(), "gt");
  auto masks = MakeSegmenter("masks:" + (dir / "masks").string(), "", settings, "");
  ASSERT_NE(masks, nullptr);
  EXPECT_EQ(masks->name(), "masks");
  EXPECT_THROW(MakeSegmenter("masks:", "", settings, ""), InputError);
  EXPECT_THROW(MakeSegmenter("maskrcnn2", "", settings, ""), InputError);
  fs::remove_all(dir);
}

TEST(SegmenterFactory, MissingModelsNameEveryPathLookedAt) {
  SegmenterSettings settings;
  const std::string e = ErrorOf([&] { MakeSegmenter("dnn", "", settings, "/nonexistent/models"); });
  EXPECT_NE(e.find("/nonexistent/models/yolox_nano/yolox_nano.onnx"), std::string::npos) << e;
  EXPECT_NE(e.find("/nonexistent/models/yolox_nano/coco.names"), std::string::npos) << e;
  EXPECT_NE(e.find("/nonexistent/models/selfie_segmentation/selfie_segmentation.onnx"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("MISSING"), std::string::npos) << e;
  const std::string m =
      ErrorOf([&] { MakeSegmenter("maskrcnn", "", settings, "/nonexistent/models"); });
  EXPECT_NE(m.find("/nonexistent/models/mask_rcnn_inception_v2_coco/frozen_inference_graph.pb"),
            std::string::npos)
      << m;
  EXPECT_NE(m.find(".pbtxt (MISSING)"), std::string::npos) << m;
}

TEST(DnnOptions, FromSettingsResolvesCompanionsAndClasses) {
  SegmenterSettings s;
  s.detector = "yolo_fastest_1.1/yolo-fastest-1.1_body.cfg";
  s.person_mask = "none";
  s.dnn.score_threshold = 0.5f;
  s.dnn.classes = {"person", "chair", "traffic light"};  // Dynamic.Classes (pipeline/settings_keys.cc)
  const DnnSegmenterOptions o = DnnOptionsFromSettings(s, "/m");
  EXPECT_EQ(o.detector_path, "/m/yolo_fastest_1.1/yolo-fastest-1.1_body.cfg");
  EXPECT_EQ(o.weights_path, "/m/yolo_fastest_1.1/yolo-fastest-1.1_body.weights");
  EXPECT_EQ(o.names_path, "/m/yolo_fastest_1.1/body.names");
  EXPECT_TRUE(o.person_mask_model.empty());
  EXPECT_FLOAT_EQ(o.score_threshold, 0.5f);
  EXPECT_EQ(o.classes, (std::vector<std::string>{"person", "chair", "traffic light"}));
  const auto looked = LookedForModels(o);
  EXPECT_EQ(looked.size(), 3u);

  const DnnSegmenterOptions d = DnnOptionsFromSettings(SegmenterSettings(), "/m");
  EXPECT_EQ(d.detector_path, "/m/yolox_nano/yolox_nano.onnx");
  EXPECT_EQ(d.names_path, "/m/yolox_nano/coco.names");
  EXPECT_EQ(d.person_mask_model, "/m/selfie_segmentation/selfie_segmentation.onnx");
  EXPECT_TRUE(d.weights_path.empty());
  EXPECT_EQ(d.classes, std::vector<std::string>{"person"});  // Dynamic.Classes' default
  std::string error;
  EXPECT_TRUE(d.Check(&error)) << error;
}

TEST(DnnOptions, CameraRateUsesItsOwnInputSize) {
  SegmenterSettings s;
  s.dnn.yolox_input_size = 448;
  s.camera_rate_input_size = 256;
  s.dnn.score_threshold = 0.4f;
  const SegmenterSettings live = ForCameraRate(s);
  EXPECT_EQ(live.dnn.yolox_input_size, 256);
  EXPECT_FLOAT_EQ(live.dnn.score_threshold, 0.4f);  // nothing else changes
  EXPECT_EQ(live.detector, s.detector);
  EXPECT_EQ(DnnOptionsFromSettings(live, "/m").yolox_input_size, 256);
  EXPECT_EQ(DnnOptionsFromSettings(s, "/m").yolox_input_size, 448);
  // The defaults: 416 offline, 256 at camera rate.
  EXPECT_EQ(SegmenterSettings().dnn.yolox_input_size, 416);
  EXPECT_EQ(ForCameraRate(SegmenterSettings()).dnn.yolox_input_size, 256);
}

TEST(DnnOptions, SecondDetectorDefaultIsOptionalAndExplicitOneIsKept) {
  // Default: the second detector is used only where its file exists in the models folder.
  SegmenterSettings none_set;
  none_set.detector = "yolox_nano/yolox_nano.onnx";
  EXPECT_TRUE(DnnOptionsFromSettings(none_set, "/no/such/models").second_detector_path.empty());
  const std::string dir = ::testing::TempDir() + "/detslam_second_detector";
  std::filesystem::create_directories(dir + "/yolo_fastest_1.1");
  std::ofstream(dir + "/yolo_fastest_1.1/yolo-fastest-1.1-xl.cfg") << "[net]\n";
  const DnnSegmenterOptions d = DnnOptionsFromSettings(SegmenterSettings(), dir);
  EXPECT_EQ(d.second_detector_path, dir + "/yolo_fastest_1.1/yolo-fastest-1.1-xl.cfg");
  EXPECT_EQ(d.second_weights_path, dir + "/yolo_fastest_1.1/yolo-fastest-1.1-xl.weights");
  EXPECT_EQ(d.second_names_path, dir + "/yolo_fastest_1.1/coco.names");
  EXPECT_FLOAT_EQ(d.second_score_threshold, 0.15f);
  const auto looked = LookedForModels(d);
  EXPECT_NE(std::find(looked.begin(), looked.end(), d.second_weights_path), looked.end());
  EXPECT_NE(std::find(looked.begin(), looked.end(), d.second_names_path), looked.end());
  // "none" turns it off even where the file exists; a named one is kept even when missing (the
  // segmenter then reports it as missing).
  SegmenterSettings off;
  off.second_detector = "none";
  EXPECT_TRUE(DnnOptionsFromSettings(off, dir).second_detector_path.empty());
  SegmenterSettings named;
  named.second_detector = "other/body.cfg";
  named.dnn.second_score_threshold = 0.3f;
  named.dnn.second_every = 3;
  EXPECT_EQ(DnnOptionsFromSettings(off, dir).second_every, 2);
  const DnnSegmenterOptions n = DnnOptionsFromSettings(named, "/m");
  EXPECT_EQ(n.second_every, 3);
  EXPECT_EQ(n.second_detector_path, "/m/other/body.cfg");
  EXPECT_EQ(n.second_weights_path, "/m/other/body.weights");
  EXPECT_FLOAT_EQ(n.second_score_threshold, 0.3f);
  std::filesystem::remove_all(dir);
}

TEST(DnnOptions, CheckRejectsBadValues) {
  DnnSegmenterOptions o;
  o.detector_path = "x.onnx";
  std::string error;
  EXPECT_TRUE(o.Check(&error)) << error;
  o.detector_path = "x.pb";
  EXPECT_FALSE(o.Check(&error));
  o.detector_path = "x.onnx";
  o.score_threshold = 1.5f;
  EXPECT_FALSE(o.Check(&error));
  o.score_threshold = 0.3f;
  o.yolox_input_size = 400;
  EXPECT_FALSE(o.Check(&error));
  EXPECT_NE(error.find("32"), std::string::npos);
  o.yolox_input_size = 416;
  o.second_detector_path = "second.pb";
  EXPECT_FALSE(o.Check(&error));
  EXPECT_NE(error.find("second"), std::string::npos) << error;
  o.second_detector_path = "second.cfg";
  EXPECT_TRUE(o.Check(&error)) << error;
  o.second_score_threshold = 0.0f;
  EXPECT_FALSE(o.Check(&error));
  o.second_score_threshold = 0.15f;
  o.second_every = 0;
  EXPECT_FALSE(o.Check(&error));
  EXPECT_NE(error.find("interval"), std::string::npos) << error;
  o.second_every = 1;
  EXPECT_TRUE(o.Check(&error)) << error;
  o.person_mask_min_fill = 1.0f;
  EXPECT_FALSE(o.Check(&error));
}

TEST(DnnOptions, DefaultModelsDirHonoursEnvironment) {
  setenv("DETSLAM_MODELS", "/tmp/my_models", 1);
  EXPECT_EQ(DefaultModelsDir(), "/tmp/my_models");
  unsetenv("DETSLAM_MODELS");
  EXPECT_FALSE(DefaultModelsDir().empty());
}

TEST(CocoClasses, NamesAndIds) {
  ASSERT_EQ(CocoClassNames().size(), 80u);
  EXPECT_EQ(CocoClassId("person"), 0);
  EXPECT_EQ(CocoClassId("body"), 0);
  EXPECT_EQ(CocoClassId("chair"), 56);
  EXPECT_EQ(CocoClassId("toothbrush"), 79);
  EXPECT_EQ(CocoClassId("unicorn"), -1);
}

}  // namespace
}  // namespace detslam
