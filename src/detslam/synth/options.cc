#include "detslam/synth/options.h"

#include <algorithm>
#include <sstream>

#include "detslam/core/check.h"

namespace detslam {

const std::vector<std::string>& SynthPresetNames() {
  static const std::vector<std::string> kNames = {
      "static",         "walking_xyz", "walking_static", "walking_rpy", "walking_halfsphere",
      "sitting_static", "loop"};
  return kNames;
}

bool IsSynthPreset(const std::string& name) {
  const auto& names = SynthPresetNames();
  return std::find(names.begin(), names.end(), name) != names.end();
}

namespace {
std::string ValidPresetList() {
  std::string out;
  for (const auto& n : SynthPresetNames()) out += (out.empty() ? "" : ", ") + n;
  return out;
}
}  // namespace

void RequireSynthPreset(const std::string& preset) {
  if (!IsSynthPreset(preset)) {
    throw InputError("unknown synth preset '" + preset + "' (valid: " + ValidPresetList() + ")");
  }
}

int SynthPresetDefaultFrames(const std::string& preset) {
  RequireSynthPreset(preset);
  if (preset == "loop") return 900;
  if (preset == "walking_halfsphere") return 900;
  if (preset == "walking_static" || preset == "sitting_static") return 700;
  return 800;
}

int SynthFrameCount(const SynthOptions& options) {
  return options.frames > 0 ? options.frames : SynthPresetDefaultFrames(options.preset);
}

bool SynthOptions::Check(std::string* error) const {
  std::ostringstream os;
  if (!IsSynthPreset(preset)) {
    os << "unknown preset '" << preset << "' (valid: " << ValidPresetList() << "); ";
  }
  if (frames == 0 || frames > 100000) os << "frames must be in 1..100000 or negative (default); ";
  if (error != nullptr) *error = os.str();
  return os.str().empty();
}

}  // namespace detslam
