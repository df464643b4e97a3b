#include "detslam/io/settings.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <opencv2/core/persistence.hpp>
#include <sstream>

#include "detslam/core/check.h"

namespace detslam {
namespace {
namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::StartsWith;

class SettingsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    static int counter = 0;
    dir_ = fs::temp_directory_path() /
           ("detslam_io_settings_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Write(const std::string& name, const std::string& text) const {
    const std::string path = (dir_ / name).string();
    std::ofstream(path) << text;
    return path;
  }
  static std::string ReadError(const std::string& path) {
    try {
      ReadSettings(path);
    } catch (const InputError& e) {
      return e.what();
    }
    ADD_FAILURE() << "no InputError for " << path;
    return "";
  }

  fs::path dir_;
};

constexpr const char* kOldStyle = R"(%YAML:1.0
---
# TUM2-like file as ORB-SLAM2 ships it
Camera.fx: 520.908620
Camera.fy: 521.007327
Camera.cx: 325.141442
Camera.cy: 249.701764
Camera.k1: 0.231222
Camera.k2: -0.784899
Camera.p1: -0.003257
Camera.p2: -0.000105
Camera.k3: 0.917205
Camera.width: 640
Camera.height: 480
Camera.fps: 30.0
Camera.bf: 40.0
Camera.RGB: 1
ThDepth: 40.0
DepthMapFactor: 5208.0
ORBextractor.nFeatures: 1500
ORBextractor.scaleFactor: 1.25
ORBextractor.nLevels: 6
ORBextractor.iniThFAST: 18
ORBextractor.minThFAST: 5
Viewer.KeyFrameSize: 0.05
Viewer.ViewpointY: -0.7
System.SaveAtlasToFile: "atlas"
LeftToRight: !!opencv-matrix
   rows: 1
   cols: 2
   dt: f
   data: [ 1.0, 2.0 ]
)";

TEST_F(SettingsTest, ReadsOldStyleOpenCvFile) {
  const std::string path = Write("old.yaml", kOldStyle);
  const Settings s = ReadSettings(path);
  EXPECT_EQ(s.source, path);
  EXPECT_DOUBLE_EQ(s.camera.fx, 520.908620);
  EXPECT_DOUBLE_EQ(s.camera.fy, 521.007327);
  EXPECT_DOUBLE_EQ(s.camera.cx, 325.141442);
  EXPECT_DOUBLE_EQ(s.camera.cy, 249.701764);
  EXPECT_DOUBLE_EQ(s.camera.k1, 0.231222);
  EXPECT_DOUBLE_EQ(s.camera.p2, -0.000105);
  EXPECT_DOUBLE_EQ(s.camera.k3, 0.917205);
  EXPECT_EQ(s.camera.width, 640);
  EXPECT_EQ(s.camera.height, 480);
  EXPECT_DOUBLE_EQ(s.camera.bf, 40.0);
  EXPECT_DOUBLE_EQ(s.camera.th_depth, 40.0);
  EXPECT_DOUBLE_EQ(s.camera.depth_map_factor, 5208.0);
  EXPECT_TRUE(s.camera.rgb_order);
  EXPECT_EQ(s.orb.n_features, 1500);
  EXPECT_DOUBLE_EQ(s.orb.scale_factor, 1.25);
  EXPECT_EQ(s.orb.n_levels, 6);
  EXPECT_EQ(s.orb.ini_th_fast, 18);
  EXPECT_EQ(s.orb.min_th_fast, 5);
  // Unconsumed scalars are kept; consumed keys and matrices are not.
  EXPECT_EQ(s.extra.size(), 3u);
  EXPECT_EQ(s.extra.at("Viewer.ViewpointY"), "-0.7");
  EXPECT_EQ(s.extra.at("System.SaveAtlasToFile"), "atlas");
  EXPECT_THAT(s.extra_origin.at("Viewer.ViewpointY"), StartsWith(path + ":"));
  EXPECT_EQ(s.extra.count("Camera.fx"), 0u);
  EXPECT_EQ(s.extra.count("LeftToRight"), 0u);
}

TEST_F(SettingsTest, ReadsV10StyleWithBaseline) {
  const std::string path = Write("v1.yaml", R"(%YAML:1.0
File.version: "1.0"
Camera.type: "PinHole"
Camera1.fx: 535.4
Camera1.fy: 539.2
Camera1.cx: 320.1
Camera1.cy: 247.6
Camera1.k1: 0.0
Camera1.k2: 0.0
Camera1.p1: 0.0
Camera1.p2: 0.0
Camera.width: 640
Camera.height: 480
Camera.fps: 30
Camera.RGB: 0
Stereo.ThDepth: 35.0
Stereo.b: 0.0747
RGBD.DepthMapFactor: 5000.0
RGBD.DisparitySigma: 0.25
)");
  const Settings s = ReadSettings(path);
  EXPECT_DOUBLE_EQ(s.camera.fx, 535.4);
  EXPECT_DOUBLE_EQ(s.camera.cy, 247.6);
  EXPECT_FALSE(s.camera.HasDistortion());
  EXPECT_DOUBLE_EQ(s.camera.bf, 0.0747 * 535.4);
  EXPECT_NEAR(s.camera.Baseline(), 0.0747, 1e-12);
  EXPECT_DOUBLE_EQ(s.camera.th_depth, 35.0);
  EXPECT_DOUBLE_EQ(s.camera.disparity_sigma, 0.25);
  EXPECT_DOUBLE_EQ(s.camera.fps, 30.0);
  EXPECT_FALSE(s.camera.rgb_order);
  EXPECT_EQ(s.orb.n_features, OrbSettings().n_features);  // defaults where absent
  EXPECT_TRUE(s.extra.empty());
}

TEST_F(SettingsTest, NestedMapsAreFlattenedToDottedKeys) {
  const std::string path = Write("nested.yaml",
                                 "Camera:\n  fx: 500\n  fy: 501\n  cx: 320\n  cy: 240\n"
                                 "  width: 640\n  height: 480\nMy:\n  flag: yes\n");
  const Settings s = ReadSettings(path);
  EXPECT_DOUBLE_EQ(s.camera.fy, 501.0);
  EXPECT_EQ(s.extra.at("My.flag"), "yes");
}

TEST_F(SettingsTest, MissingRequiredKeysNameFileAndKey) {
  for (const std::string key :
       {"Camera.fx", "Camera.fy", "Camera.cx", "Camera.cy", "Camera.width", "Camera.height"}) {
    std::istringstream in(kOldStyle);
    std::string text, line;
    while (std::getline(in, line)) {
      if (line.rfind(key + ":", 0) != 0) text += line + "\n";
    }
    const std::string path = Write("missing.yaml", text);
    const std::string error = ReadError(path);
    EXPECT_THAT(error, HasSubstr(path));
    EXPECT_THAT(error, HasSubstr("missing required key '" + key + "'"));
  }
  const std::string v1 = Write("v1_missing.yaml",
                               "File.version: \"1.0\"\nCamera1.fx: 1.0\nCamera1.fy: 1.0\n"
                               "Camera1.cx: 1.0\nCamera.width: 640\nCamera.height: 480\n");
  EXPECT_THAT(ReadError(v1), HasSubstr("'Camera1.cy'"));
}

TEST_F(SettingsTest, WrongTypeNamesFileLineAndKey) {
  std::string text = kOldStyle;
  text.replace(text.find("Camera.width: 640"), 17, "Camera.width: wide");
  const std::string path = Write("wrong.yaml", text);
  EXPECT_THAT(ReadError(path), HasSubstr(path + ":13: key 'Camera.width' must be an integer"));
  text = kOldStyle;
  text.replace(text.find("Camera.RGB: 1"), 13, "Camera.RGB: maybe");
  EXPECT_THAT(ReadError(Write("wrong2.yaml", text)), HasSubstr("'Camera.RGB'"));
  text = kOldStyle;
  text.replace(text.find("Camera.cx: 325.141442"), 21, "Camera.cx: [1, 2]");
  // A sequence is not a scalar, so the required key counts as missing.
  EXPECT_THAT(ReadError(Write("wrong3.yaml", text)), HasSubstr("'Camera.cx'"));
}

TEST_F(SettingsTest, CameraAndOrbChecksAreReportedWithTheFile) {
  std::string text = kOldStyle;
  text.replace(text.find("DepthMapFactor: 5208.0"), 22, "DepthMapFactor: 0.0");
  const std::string path = Write("check.yaml", text);
  const std::string error = ReadError(path);
  EXPECT_THAT(error, StartsWith(path));
  EXPECT_THAT(error, HasSubstr("DepthMapFactor must be positive"));
  text = std::string(kOldStyle) + "DisparitySigma: -0.1\n";
  EXPECT_THAT(ReadError(Write("disparity.yaml", text)), HasSubstr("DisparitySigma must be >= 0"));
  for (const char* readout : {"-0.01", "0.05"}) {  // negative; longer than a frame at 30 fps
    text = std::string(kOldStyle) + "Camera.RollingShutterReadout: " + readout + "\n";
    EXPECT_THAT(ReadError(Write("readout.yaml", text)),
                HasSubstr("RollingShutterReadout must be in [0, 1/fps]"))
        << readout;
  }
  text = kOldStyle;
  text.replace(text.find("ORBextractor.scaleFactor: 1.25"), 30, "ORBextractor.scaleFactor: 0.9");
  EXPECT_THAT(ReadError(Write("orb.yaml", text)), HasSubstr("scaleFactor"));
}

TEST_F(SettingsTest, BadFilesAreErrors) {
  EXPECT_THAT(ReadError((dir_ / "absent.yaml").string()), HasSubstr("absent.yaml"));
  EXPECT_THAT(ReadError(Write("empty.yaml", "%YAML:1.0\n---\n")), HasSubstr("empty"));
  EXPECT_THAT(ReadError(Write("list.yaml", "- 1\n- 2\n")), HasSubstr("map"));
  const std::string syntax = Write("syntax.yaml", "Camera.fx: 1\nCamera.fy: [1, 2\n");
  EXPECT_THAT(ReadError(syntax), HasSubstr(syntax + ":"));
  EXPECT_THAT(ReadError(syntax), HasSubstr("YAML syntax error"));
  EXPECT_THAT(ReadError(Write("complex_key.yaml", "? [a, b]\n: 1\n")),
              HasSubstr("unsupported YAML structure"));
  EXPECT_THAT(ReadError(Write("version.yaml", "File.version: \"2.0\"\n")),
              HasSubstr("File.version '2.0'"));
  EXPECT_THAT(
      ReadError(Write("fisheye.yaml", "File.version: \"1.0\"\nCamera.type: \"KannalaBrandt8\"\n")),
      HasSubstr("KannalaBrandt8"));
}

TEST_F(SettingsTest, OverridesSetKeysAndAreNamedInTheSource) {
  Settings s;
  s.source = "cfg.yaml";
  s.extra = {{"Dynamic.Alpha", "0.1"}};
  ApplySettingOverrides({"Dynamic.Alpha=0.2", "Segmentation.SecondEvery=1"}, &s);
  EXPECT_EQ(s.extra.at("Dynamic.Alpha"), "0.2");
  EXPECT_EQ(s.extra.at("Segmentation.SecondEvery"), "1");
  EXPECT_EQ(s.source, "cfg.yaml + --set Dynamic.Alpha=0.2 + --set Segmentation.SecondEvery=1");
  // Each key remembers the override that set it, for error messages (pipeline/settings_keys.h).
  EXPECT_EQ(s.extra_origin.at("Dynamic.Alpha"), "--set Dynamic.Alpha=0.2");
  // The depth weighting is the one camera-section key that --set may change.
  ApplySettingOverrides({"RGBD.DisparitySigma=0"}, &s);
  EXPECT_DOUBLE_EQ(s.camera.disparity_sigma, 0.0);
  for (const std::string bad : {"NoValue", "=1", "Key=", "Camera.fx=500", "ORBextractor.nFeatures=10",
                                "RGBD.DisparitySigma=-1", "RGBD.DisparitySigma=x",
                                "RGBD.DepthMapFactor=1000"}) {
    Settings t;
    EXPECT_THROW(ApplySettingOverrides({bad}, &t), InputError) << bad;
  }
}

TEST_F(SettingsTest, WriteReadRoundTripIsOpenCvReadable) {
  Settings s = PresetByName("fr2");
  s.camera.fx = 520.0;  // integral value must still be written as a real
  s.camera.bf = 0.075 * 520.0;
  s.camera.disparity_sigma = 0.0;  // ORB-SLAM3's u_right model survives the round trip
  s.orb.n_features = 1234;
  s.extra = {{"Viewer.KeyFrameSize", "0.05"},
             {"System.SaveAtlasToFile", "my map \"v2\".osa"},
             {"Custom.flag", "true"},
             {"Camera1.fx", "999"}};  // clashes with a written key: skipped
  const std::string path = (dir_ / "sub" / "out.yaml").string();
  WriteSettings(path, s);
  EXPECT_FALSE(fs::exists(path + ".tmp"));
  std::ifstream in(path);
  std::string first;
  std::getline(in, first);
  EXPECT_EQ(first, "%YAML:1.0");

  const Settings back = ReadSettings(path);
  EXPECT_DOUBLE_EQ(back.camera.fx, 520.0);
  EXPECT_DOUBLE_EQ(back.camera.fy, s.camera.fy);
  EXPECT_DOUBLE_EQ(back.camera.cx, s.camera.cx);
  EXPECT_DOUBLE_EQ(back.camera.cy, s.camera.cy);
  EXPECT_DOUBLE_EQ(back.camera.k1, s.camera.k1);
  EXPECT_DOUBLE_EQ(back.camera.k2, s.camera.k2);
  EXPECT_DOUBLE_EQ(back.camera.p1, s.camera.p1);
  EXPECT_DOUBLE_EQ(back.camera.p2, s.camera.p2);
  EXPECT_DOUBLE_EQ(back.camera.k3, s.camera.k3);
  EXPECT_NEAR(back.camera.bf, s.camera.bf, 1e-9);
  EXPECT_DOUBLE_EQ(back.camera.depth_map_factor, 5208.0);
  EXPECT_DOUBLE_EQ(back.camera.th_depth, s.camera.th_depth);
  EXPECT_DOUBLE_EQ(back.camera.disparity_sigma, 0.0);
  EXPECT_DOUBLE_EQ(back.camera.rolling_shutter_readout, 0.0);  // a global shutter: not written
  EXPECT_EQ(back.camera.width, s.camera.width);
  EXPECT_EQ(back.orb.n_features, 1234);
  EXPECT_DOUBLE_EQ(back.orb.scale_factor, s.orb.scale_factor);
  std::map<std::string, std::string> expected_extra = s.extra;
  expected_extra.erase("Camera1.fx");
  EXPECT_EQ(back.extra, expected_extra);

  // OpenCV FileStorage (what ORB-SLAM3 uses) parses it with the types ORB-SLAM3 v1.0 expects.
  cv::FileStorage fs(path, cv::FileStorage::READ);
  ASSERT_TRUE(fs.isOpened());
  EXPECT_TRUE(fs["File.version"].isString());
  EXPECT_EQ(static_cast<std::string>(fs["Camera.type"]), "PinHole");
  EXPECT_TRUE(fs["Camera1.fx"].isReal());
  EXPECT_DOUBLE_EQ(static_cast<double>(fs["Camera1.fx"]), 520.0);
  EXPECT_TRUE(fs["Stereo.b"].isReal());
  EXPECT_TRUE(fs["RGBD.DepthMapFactor"].isReal());
  EXPECT_TRUE(fs["Camera.width"].isInt());
  EXPECT_TRUE(fs["Camera.fps"].isInt());
  EXPECT_TRUE(fs["ORBextractor.nFeatures"].isInt());
  EXPECT_TRUE(fs["ORBextractor.scaleFactor"].isReal());
  EXPECT_TRUE(fs["Camera.RollingShutterReadout"].empty());

  // A rolling shutter's readout time survives the round trip.
  s.camera.rolling_shutter_readout = 0.025;
  WriteSettings(path, s);
  EXPECT_DOUBLE_EQ(ReadSettings(path).camera.rolling_shutter_readout, 0.025);
}

}  // namespace
}  // namespace detslam
