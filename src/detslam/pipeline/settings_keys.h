// detslam's own settings keys (Tracking.*, LocalMapping.*, LoopClosing.*, Place.*, Dynamic.*,
// Segmentation.*, and RGBD.DisparitySigma), each declared once in settings_keys.cc with its type,
// range and help and bound to the options field it fills; the default of a key is that field's
// in-class default. `detslam settings --list` prints them.
#pragma once

#include <nlohmann/json_fwd.hpp>
#include <string>
#include <utility>
#include <vector>

#include "detslam/core/camera.h"
#include "detslam/io/setting_spec.h"
#include "detslam/io/settings.h"
#include "detslam/pipeline/runner.h"
#include "detslam/segmentation/segmenter_settings.h"

namespace detslam {

// The typed values of the declared keys: the options structs they fill.
struct ResolvedSettings {
  RunOptions
      run;  // run.slam (Tracking.*, LocalMapping.*, LoopClosing.*, Dynamic.*, Segmentation.EveryK)
  SegmenterSettings segmenter;  // Segmentation.* and Dynamic.Classes
  PinholeCamera camera;         // RGBD.DisparitySigma (read with the camera keys by ReadSettings)
};

// Every declared key in listing order; default_value is the default-constructed structs' value.
const std::vector<SettingSpec>& DeclaredSettings();

// The typed values of `settings.extra` over the defaults (and settings.camera). Throws InputError
// naming where the key came from (FILE:LINE or the --set item) and the key for
//   - a value of the wrong type or out of range,
//   - a renamed key (Segmentation.DynamicClasses: use Dynamic.Classes),
//   - an undeclared key from --set, or from a file in detslam's own namespaces (Tracking.,
//     LocalMapping., LoopClosing., Place., Dynamic., Segmentation.), with the closest declared
//     key.
// Other keys of a file (ORB-SLAM3's Viewer.*, System.*, IMU.*, ...) are ignored (debug log).
ResolvedSettings ResolveSettings(const Settings& settings);

// The value of every declared key in `resolved`, in listing order.
std::vector<std::pair<std::string, SettingValue>> SettingValues(const ResolvedSettings& resolved);

// run.json's "effective_settings": every declared key's value as the run used it, from `settings`
// with `options` (which command-line flags such as --alpha may have changed) for the run's keys.
nlohmann::json EffectiveSettingsJson(const Settings& settings, const RunOptions& options);

}  // namespace detslam
