// Built-in camera presets (values as in ORB-SLAM3's TUM1/2/3.yaml and the Bonn RGB-D Dynamic
// dataset's calibration) and the choice of a preset from a dataset folder's name.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <vector>

#include "detslam/core/check.h"
#include "detslam/io/settings.h"

namespace detslam {
namespace fs = std::filesystem;
namespace {

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

// Common to all presets: 640x480 Kinect-class sensors at 30 Hz, bf 40, ThDepth 40.
Settings Base(const std::string& name) {
  Settings s;
  s.source = "preset " + name;
  s.camera.width = 640;
  s.camera.height = 480;
  s.camera.fps = 30.0;
  s.camera.bf = 40.0;
  s.camera.th_depth = 40.0;
  s.camera.rgb_order = true;
  s.camera.depth_map_factor = 5000.0;
  return s;
}

void SetIntrinsics(PinholeCamera* c, double fx, double fy, double cx, double cy) {
  c->fx = fx;
  c->fy = fy;
  c->cx = cx;
  c->cy = cy;
}

void SetDistortion(PinholeCamera* c, double k1, double k2, double p1, double p2, double k3) {
  c->k1 = k1;
  c->k2 = k2;
  c->p1 = p1;
  c->p2 = p2;
  c->k3 = k3;
}

}  // namespace

Settings PresetByName(const std::string& name) {
  const std::string n = Lower(name);
  if (n == "fr1" || n == "freiburg1") {
    Settings s = Base("fr1");
    SetIntrinsics(&s.camera, 517.306408, 516.469215, 318.643040, 255.313989);
    SetDistortion(&s.camera, 0.262383, -0.953104, -0.005358, 0.002628, 1.163314);
    return s;
  }
  if (n == "fr2" || n == "freiburg2") {
    Settings s = Base("fr2");
    SetIntrinsics(&s.camera, 520.908620, 521.007327, 325.141442, 249.701764);
    SetDistortion(&s.camera, 0.231222, -0.784899, -0.003257, -0.000105, 0.917205);
    s.camera.depth_map_factor = 5208.0;  // ORB-SLAM's depth-scale correction for fr2's sensor
    return s;
  }
  if (n == "fr3" || n == "freiburg3") {
    Settings s = Base("fr3");
    SetIntrinsics(&s.camera, 535.4, 539.2, 320.1, 247.6);  // images are already undistorted
    return s;
  }
  if (n == "bonn") {
    Settings s = Base("bonn");
    SetIntrinsics(&s.camera, 542.822841, 542.576870, 315.593520, 237.756098);
    SetDistortion(&s.camera, 0.039903, -0.099343, -0.000730, -0.000144, 0.000920);
    return s;
  }
  throw InputError("unknown settings preset '" + name + "' (known: fr1, fr2, fr3, bonn)");
}

Settings PresetForDataset(const std::string& dataset_dir) {
  const fs::path own = fs::path(dataset_dir) / "settings.yaml";
  if (fs::is_regular_file(own)) {
    spdlog::info("using the dataset's own settings {}", own.string());
    return ReadSettings(own.string());
  }
  fs::path dir = fs::path(dataset_dir).lexically_normal();
  if (dir.filename().empty()) dir = dir.parent_path();  // trailing slash
  if (dir.filename() == "." || dir.filename().empty()) dir = fs::absolute(dir).lexically_normal();
  if (dir.filename().empty()) dir = dir.parent_path();
  const std::string folder = Lower(dir.filename().string());

  const std::vector<std::pair<std::string, std::vector<std::string>>> patterns = {
      {"fr1", {"freiburg1", "fr1"}},
      {"fr2", {"freiburg2", "fr2"}},
      {"fr3", {"freiburg3", "fr3"}},
      {"bonn", {"bonn"}}};
  std::vector<std::string> matches;
  for (const auto& [preset, needles] : patterns) {
    for (const std::string& needle : needles) {
      if (folder.find(needle) != std::string::npos) {
        matches.push_back(preset);
        break;
      }
    }
  }
  if (matches.empty()) {
    throw InputError(dataset_dir, 0,
                     "no camera preset matches the folder name '" + folder +
                         "' (looked for freiburg1/fr1, freiburg2/fr2, freiburg3/fr3, bonn) and "
                         "there is no settings.yaml in it; pass the settings with --config FILE");
  }
  if (matches.size() > 1) {
    throw InputError(dataset_dir, 0,
                     "folder name '" + folder + "' matches several camera presets (" + matches[0] +
                         ", " + matches[1] + "); pass the settings with --config FILE");
  }
  spdlog::info("{}: using camera preset {}", dataset_dir, matches[0]);
  return PresetByName(matches[0]);
}

}  // namespace detslam
