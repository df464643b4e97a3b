// Helpers shared by the integration tests (header-only; tests/ only).
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "detslam/synth/writer.h"
#include "support/cli_runner.h"

namespace detslam::integration {

// A synthetic `static` sequence (people in it unless `people` is false) in a fresh temporary
// folder named `name`; returns the folder.
inline std::string WriteStaticSequence(const std::string& name, uint64_t seed, int frames,
                                       bool people = true) {
  const std::string dir = testing::TempDir(name);
  SynthOptions so;
  so.preset = "static";
  so.seed = seed;
  so.frames = frames;
  so.people = people;
  WriteSequence(so, dir);
  return dir;
}

// A synthetic sequence of `preset` in a fresh temporary folder named `name`; returns the folder.
inline std::string WritePresetSequence(const std::string& name, const std::string& preset,
                                       uint64_t seed, int frames) {
  const std::string dir = testing::TempDir(name);
  SynthOptions so;
  so.preset = preset;
  so.seed = seed;
  so.frames = frames;
  WriteSequence(so, dir);
  return dir;
}

// The run.json of a run's output folder.
inline nlohmann::json RunJson(const std::filesystem::path& out) {
  return nlohmann::json::parse(testing::ReadFileBytes(out / "run.json"));
}

}  // namespace detslam::integration
