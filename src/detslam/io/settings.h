// ORB-SLAM3-style settings files (YAML as OpenCV FileStorage writes it: `%YAML:1.0` header, flat
// dotted keys). Both key styles are read:
//   old (ORB-SLAM2 / ORB-SLAM3 0.x): Camera.fx fy cx cy k1 k2 p1 p2 k3 width height fps bf RGB,
//                                    ThDepth, DepthMapFactor
//   v1.0 (File.version: "1.0"):      Camera1.fx ... Camera1.k3, Camera.width height fps RGB,
//                                    Stereo.ThDepth, Stereo.b (bf = b * fx), RGBD.DepthMapFactor
// plus ORBextractor.*. Every other scalar key is kept as text in `extra` (detslam's own keys are
// declared, typed and checked in pipeline/settings_keys.h). YAML is parsed here
// only; algorithms receive the plain structs.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "detslam/core/camera.h"

namespace detslam {

// ORB extractor parameters as read from the settings (features/ converts them to its options).
struct OrbSettings {
  int n_features = 1000;      // ORBextractor.nFeatures: keypoints per image
  double scale_factor = 1.2;  // ORBextractor.scaleFactor: pyramid scale between levels
  int n_levels = 8;           // ORBextractor.nLevels: pyramid levels
  int ini_th_fast = 20;       // ORBextractor.iniThFAST: FAST threshold tried first
  int min_th_fast = 7;        // ORBextractor.minThFAST: FAST threshold if a cell yields nothing

  bool Check(std::string* error) const;
};

struct Settings {
  PinholeCamera camera;                      // intrinsics, distortion and depth conventions
  OrbSettings orb;                           // ORB extractor parameters
  std::map<std::string, std::string> extra;  // all other scalar keys, value as text
  // Where each extra key came from, for error messages: "FILE:LINE" or "--set KEY=VALUE"
  // (absent: `source`). detslam's own keys are typed and checked by pipeline/settings_keys.h.
  std::map<std::string, std::string> extra_origin;
  std::string source;  // file path or "preset <name>"
};

// Reads a settings file. Throws InputError naming the file (and line / key) if the file is
// missing or not YAML, a required key (fx fy cx cy width height) is missing, a value has the
// wrong type, or the camera / ORB parameters fail their checks.
Settings ReadSettings(const std::string& path);

// Writes v1.0-style settings atomically, starting with `%YAML:1.0` so that OpenCV FileStorage
// (ORB-SLAM3) reads it too; real-valued keys always carry a decimal point. Extra keys follow.
void WriteSettings(const std::string& path, const Settings& settings);

// Built-in camera presets: "fr1", "fr2", "fr3" (TUM RGB-D Kinects, ORB-SLAM3's TUM1/2/3.yaml
// values; "freiburg1" etc. also accepted) and "bonn" (Bonn RGB-D Dynamic). Throws InputError for
// an unknown name.
Settings PresetByName(const std::string& name);

// Settings for a dataset folder: its own settings.yaml if present, else the preset whose name
// appears in the folder's name (freiburg1/fr1, freiburg2/fr2, freiburg3/fr3, bonn). Throws
// InputError if none matches (the user must pass --config FILE).
Settings PresetForDataset(const std::string& dataset_dir);

// Applies command-line overrides "KEY=VALUE" (`--set`) to the extra keys (Tracking.*,
// LocalMapping.*, Dynamic.*, Segmentation.*, ...) and RGBD.DisparitySigma. Throws InputError for
// a malformed item or a camera/ORB key (those come from the settings file); unknown keys are
// rejected when the settings are resolved (pipeline/settings_keys.h).
void ApplySettingOverrides(const std::vector<std::string>& overrides, Settings* settings);

}  // namespace detslam
