// Helpers shared by the integration tests (header-only; tests/ only).
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "detslam/synth/writer.h"
#include "support/cli_runner.h"

namespace detslam::integration {

// Every option that changes a synthetic sequence, as a file name (the cache key below).
inline std::string SequenceKey(const SynthOptions& so) {
  static_assert(sizeof(SynthOptions) == 152, "a new SynthOptions field: add it to SequenceKey");
  std::ostringstream all;
  all.precision(17);
  all << so.preset << '|' << so.seed << '|' << so.scene_seed << '|' << so.frames << '|'
      << so.people_dir << '|' << so.people << so.motion_blur << so.sensor_noise << '|'
      << SynthRealismName(so.realism) << '|';
  for (const std::string& e : so.realism_off) all << e << ',';
  all << '|' << so.depth_scale_bias << '|' << so.cut_begin << ':' << so.cut_end << '|'
      << so.cover_start_s << ':' << so.cover_seconds;
  uint64_t h = 1469598103934665603ULL;  // FNV-1a 64
  for (const unsigned char c : all.str()) h = (h ^ c) * 1099511628211ULL;
  std::ostringstream key;
  key << so.preset << '_' << so.seed << '_' << std::hex << h;
  return key.str();
}

// Writes the synthetic sequence of `so` into `dir`. With DETSLAM_TEST_SEQUENCE_CACHE set (.ci/run
// sets it to a fresh folder), a sequence that an earlier test already rendered, in this build or
// another (CI's sanitizer stages take the Release stage's), is copied from there instead of being
// rendered again: most of an integration test's time under ThreadSanitizer went to rendering.
// The first test to render one stores it there (a temporary folder renamed into place; when two
// tests race, the first rename wins). The generator's own tests never use this.
inline void WriteTestSequence(const SynthOptions& so, const std::string& dir) {
  namespace fs = std::filesystem;
  const char* cache = std::getenv("DETSLAM_TEST_SEQUENCE_CACHE");
  if (cache == nullptr || *cache == '\0') {
    WriteSequence(so, dir);
    return;
  }
  const fs::path entry = fs::path(cache) / SequenceKey(so);
  if (!fs::exists(entry)) {
    fs::create_directories(cache);
    const fs::path tmp = entry.string() + ".tmp" + std::to_string(::getpid());
    WriteSequence(so, tmp.string());
    std::error_code ec;
    fs::rename(tmp, entry, ec);
    if (ec) fs::remove_all(tmp);  // another test stored it meanwhile
  }
  fs::copy(entry, dir, fs::copy_options::recursive | fs::copy_options::overwrite_existing);
}

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
  WriteTestSequence(so, dir);
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
  WriteTestSequence(so, dir);
  return dir;
}

// The run.json of a run's output folder.
inline nlohmann::json RunJson(const std::filesystem::path& out) {
  return nlohmann::json::parse(testing::ReadFileBytes(out / "run.json"));
}

}  // namespace detslam::integration
