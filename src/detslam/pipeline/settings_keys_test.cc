#include "detslam/pipeline/settings_keys.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <set>

#include "detslam/core/check.h"
#include "support/cli_runner.h"

namespace detslam {
namespace {
namespace fs = std::filesystem;
using ::testing::HasSubstr;

std::string ErrorOf(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const InputError& e) {
    return e.what();
  }
  return "no InputError";
}

// A v1.0 settings file with the camera and `more` appended.
std::string WriteSettingsFile(const std::string& name, const std::string& more) {
  const fs::path path = testing::TempPath("keys_" + name);
  std::ofstream(path)
      << "%YAML:1.0\nFile.version: \"1.0\"\nCamera.type: \"PinHole\"\nCamera1.fx: 535.4\n"
         "Camera1.fy: 539.2\nCamera1.cx: 320.1\nCamera1.cy: 247.6\nCamera.width: 640\n"
         "Camera.height: 480\nCamera.fps: 30\n"
      << more;
  return path.string();
}

Settings WithSet(const std::vector<std::string>& overrides) {
  Settings s;
  s.source = "preset fr3";
  ApplySettingOverrides(overrides, &s);
  return s;
}

TEST(SettingsKeysTest, EveryKeyIsDeclaredOnceWithTheOptionsStructDefault) {
  std::set<std::string> seen;
  for (const SettingSpec& spec : DeclaredSettings()) {
    EXPECT_TRUE(seen.insert(spec.key).second) << spec.key << " declared twice";
    EXPECT_FALSE(spec.help.empty()) << spec.key;
    std::string why;
    SettingValue back;
    // The default reads back through its own spec (type and range admit it).
    EXPECT_TRUE(ParseSettingValue(spec, FormatSettingValue(spec.default_value), &back, &why))
        << spec.key << ": " << why;
  }
  // Defaults are the structs' in-class ones: resolving no keys gives default-constructed options.
  const ResolvedSettings r = ResolveSettings(Settings());
  const SlamOptions slam;
  EXPECT_DOUBLE_EQ(r.run.slam.dynamic.filter.alpha, slam.dynamic.filter.alpha);
  EXPECT_EQ(r.run.slam.dynamic.filter.dynamic_classes, slam.dynamic.filter.dynamic_classes);
  EXPECT_EQ(r.run.slam.tracker.keyframe_far_points, slam.tracker.keyframe_far_points);
  EXPECT_EQ(r.run.slam.dynamic.segment_every, DetSlamOptions().segment_every);
  // The segmenters return the dynamic classes only, by default too.
  EXPECT_EQ(r.segmenter.dnn.classes, slam.dynamic.filter.dynamic_classes);
  EXPECT_EQ(r.segmenter.maskrcnn.classes, slam.dynamic.filter.dynamic_classes);
  EXPECT_FLOAT_EQ(r.segmenter.maskrcnn.score_threshold, MaskRcnnOptions().score_threshold);
  const std::vector<std::pair<std::string, SettingValue>> values = SettingValues(r);
  ASSERT_EQ(values.size(), DeclaredSettings().size());
  for (size_t i = 0; i < values.size(); ++i) {
    EXPECT_EQ(FormatSettingValue(values[i].second),
              FormatSettingValue(DeclaredSettings()[i].default_value))
        << values[i].first;
  }
  auto find = [](const std::string& key) {
    for (const SettingSpec& s : DeclaredSettings()) {
      if (s.key == key) return FormatSettingValue(s.default_value);
    }
    return std::string("undeclared");
  };
  EXPECT_EQ(find("Dynamic.Alpha"), "0.1");
  EXPECT_EQ(find("Dynamic.Classes"), "person");
  EXPECT_EQ(find("Segmentation.ScoreThreshold"), "0.35");
  EXPECT_EQ(find("Segmentation.EveryK"), "1");
  EXPECT_EQ(find("RGBD.DisparitySigma"), "0.1");
  EXPECT_EQ(find("Segmentation.DynamicClasses"), "undeclared");
}

TEST(SettingsKeysTest, KeysFillTheirFields) {
  const ResolvedSettings r =
      ResolveSettings(WithSet({"Dynamic.Alpha=0.25", "LoopClosing.Enabled=off",
                               "Dynamic.Classes=person, chair", "Segmentation.EveryK=3",
                               "Segmentation.ScoreThreshold=0.4", "Segmentation.Detector=x.onnx"}));
  EXPECT_DOUBLE_EQ(r.run.slam.dynamic.filter.alpha, 0.25);
  EXPECT_FALSE(r.run.slam.loop.enabled);
  EXPECT_EQ(r.run.slam.dynamic.segment_every, 3);
  EXPECT_EQ(r.segmenter.detector, "x.onnx");
  // One key for the dynamic classes: the keypoint filter's and the segmenter's.
  const std::vector<std::string> classes = {"person", "chair"};
  EXPECT_EQ(r.run.slam.dynamic.filter.dynamic_classes, classes);
  EXPECT_EQ(r.segmenter.dnn.classes, classes);
  EXPECT_EQ(r.segmenter.maskrcnn.classes, classes);
  EXPECT_FLOAT_EQ(r.segmenter.dnn.score_threshold, 0.4f);
  EXPECT_FLOAT_EQ(r.segmenter.maskrcnn.score_threshold, 0.4f);
  EXPECT_EQ(
      SlamOptionsFromSettings(WithSet({"Dynamic.MaskDilation=7"}), 1).dynamic.filter.mask_dilation_px, 7);
  EXPECT_EQ(SlamOptionsFromSettings(WithSet({"Segmentation.CarryGrowth=5"}), 1)
                .dynamic.propagation.grow_px_per_frame,
            5);
}

// --seed reaches every RANSAC: relocalisation and loop verification.
TEST(SettingsKeysTest, TheSeedReachesTrackingAndLoopClosing) {
  const SlamOptions o = SlamOptionsFromSettings(WithSet({}), 1234);
  EXPECT_EQ(o.tracker.seed, 1234u);
  EXPECT_EQ(o.loop.seed, 1234u);
}

TEST(SettingsKeysTest, UnknownSetKeyIsAnErrorNamingTheClosestKey) {
  EXPECT_THAT(
      ErrorOf([] { ResolveSettings(WithSet({"Dynamic.Alpah=0.5"})); }),
      HasSubstr(
          "--set Dynamic.Alpah=0.5: unknown key 'Dynamic.Alpah'; did you mean 'Dynamic.Alpha'?"));
  // Any undeclared key, not only detslam's namespaces.
  EXPECT_THAT(ErrorOf([] { ResolveSettings(WithSet({"Viewer.KeyFrameSize=1"})); }),
              HasSubstr("unknown key 'Viewer.KeyFrameSize'"));
  EXPECT_THAT(ErrorOf([] { ResolveSettings(WithSet({"Tracking.X=abc"})); }),
              HasSubstr("--set Tracking.X=abc: unknown key"));
}

TEST(SettingsKeysTest, TypeAndRangeErrorsNameTheKeyAndWhereItCameFrom) {
  EXPECT_THAT(
      ErrorOf([] { ResolveSettings(WithSet({"Dynamic.MaskDilation=abc"})); }),
      HasSubstr("--set Dynamic.MaskDilation=abc: key 'Dynamic.MaskDilation' must be an integer"));
  EXPECT_THAT(ErrorOf([] { ResolveSettings(WithSet({"Segmentation.EveryK=0"})); }),
              HasSubstr("key 'Segmentation.EveryK' must be in [1, inf], got '0'"));
  EXPECT_THAT(ErrorOf([] { ResolveSettings(WithSet({"LocalMapping.Triangulate=maybe"})); }),
              HasSubstr("must be a boolean"));
  const std::string path = WriteSettingsFile("range.yaml", "Dynamic.MinScore: 2.0\n");
  EXPECT_THAT(ErrorOf([&] { ResolveSettings(ReadSettings(path)); }),
              HasSubstr(path + ":11: key 'Dynamic.MinScore' must be in [0, 1], got '2.0'"));
}

TEST(SettingsKeysTest, UnknownKeyInOwnNamespaceOfAFileIsAnError) {
  const std::string path =
      WriteSettingsFile("typo.yaml", "Viewer.KeyFrameSize: 0.05\nLoopClosing.Enable: 0\n");
  EXPECT_THAT(
      ErrorOf([&] { ResolveSettings(ReadSettings(path)); }),
      HasSubstr(path +
                ":12: unknown key 'LoopClosing.Enable'; did you mean 'LoopClosing.Enabled'?"));
}

TEST(SettingsKeysTest, OrbSlam3KeysOfAFileAreIgnored) {
  const std::string path = WriteSettingsFile(
      "orbslam3.yaml",
      "Viewer.KeyFrameSize: 0.05\nViewer.ViewpointY: -0.7\nSystem.SaveAtlasToFile: \"atlas\"\n"
      "IMU.Frequency: 200\nCamera.newWidth: 600\nRGBD.DisparitySigma: 0.2\nDynamic.Alpha: 0.3\n");
  const Settings settings = ReadSettings(path);
  const ResolvedSettings r = ResolveSettings(settings);
  EXPECT_DOUBLE_EQ(r.run.slam.dynamic.filter.alpha, 0.3);
  EXPECT_DOUBLE_EQ(r.camera.disparity_sigma, 0.2);
  EXPECT_DOUBLE_EQ(settings.camera.disparity_sigma, 0.2);
}

TEST(SettingsKeysTest, SegmentationDynamicClassesWasRenamed) {
  EXPECT_THAT(ErrorOf([] { ResolveSettings(WithSet({"Segmentation.DynamicClasses=person"})); }),
              HasSubstr("key 'Segmentation.DynamicClasses' was renamed to 'Dynamic.Classes'"));
  const std::string path =
      WriteSettingsFile("renamed.yaml", "Segmentation.DynamicClasses: \"person\"\n");
  EXPECT_THAT(ErrorOf([&] { ResolveSettings(ReadSettings(path)); }),
              HasSubstr(path + ":11: key 'Segmentation.DynamicClasses' was renamed"));
}

TEST(SettingsKeysTest, EffectiveSettingsJsonHasEveryKeyWithTheRunsValues) {
  RunOptions options;
  options.slam.dynamic.filter.alpha = 0.5;  // e.g. from --alpha
  options.slam.dynamic.segment_every = 4;
  const nlohmann::json j =
      EffectiveSettingsJson(WithSet({"Segmentation.PersonMask=none"}), options);
  EXPECT_EQ(j.size(), DeclaredSettings().size());
  EXPECT_DOUBLE_EQ(j["Dynamic.Alpha"].get<double>(), 0.5);
  EXPECT_EQ(j["Segmentation.EveryK"].get<int>(), 4);
  EXPECT_EQ(j["Segmentation.PersonMask"], "none");
  EXPECT_EQ(j["LoopClosing.Enabled"], true);
  EXPECT_EQ(j["Dynamic.Classes"], nlohmann::json::array({"person"}));
  EXPECT_DOUBLE_EQ(j["Segmentation.ScoreThreshold"].get<double>(), 0.35);
}

}  // namespace
}  // namespace detslam
