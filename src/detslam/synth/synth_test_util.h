// Helpers shared by the synth module's tests.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "detslam/synth/options.h"

namespace detslam::synth_test {

inline SynthOptions Opts(const std::string& preset, uint64_t seed = 1, bool noise = true) {
  SynthOptions o;
  o.preset = preset;
  o.seed = seed;
  o.sensor_noise = noise;
  return o;
}

// The error message of SynthOptions::Check, or "" if the options are valid.
inline std::string CheckError(const SynthOptions& o) {
  std::string error;
  return o.Check(&error) ? "" : error;
}

// The whole file as bytes ("" if it cannot be read).
inline std::string Slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

// An empty temporary folder of this process for test `name` (removed first if it exists).
inline std::filesystem::path TempDir(const std::string& prefix, const std::string& name) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    (prefix + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  return dir;
}

}  // namespace detslam::synth_test
