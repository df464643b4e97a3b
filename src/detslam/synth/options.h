// Options of the synthetic dynamic RGB-D sequence generator (`detslam synth`).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace detslam {

struct SynthOptions {
  std::string preset = "walking_xyz";  // camera/people script, one of SynthPresetNames()
  uint64_t seed = 1;                   // seeds textures, people and sensor noise
  int frames = -1;                     // number of frames; <= 0: the preset's default length
  std::string people_dir;              // folder with person_*.png RGBA cut-outs; empty: procedural
  bool people = true;                  // false: the static twin (same camera path, no people)
  bool motion_blur = false;            // blur colour images along the camera's image motion
  bool sensor_noise = true;            // false: ideal depth and colour (tests of the geometry)

  // True if the options are valid; otherwise fills `error` (may be null) with the reasons.
  bool Check(std::string* error) const;
};

// The valid preset names, in a fixed order.
const std::vector<std::string>& SynthPresetNames();

// True if `name` is a preset.
bool IsSynthPreset(const std::string& name);

// Default number of frames of a preset (30 Hz). The preset must exist.
int SynthPresetDefaultFrames(const std::string& preset);

// The number of frames the options ask for (their `frames` or the preset's default).
int SynthFrameCount(const SynthOptions& options);

// Throws InputError if the preset is unknown (the message lists the valid ones).
void RequireSynthPreset(const std::string& preset);

}  // namespace detslam
