// Fuzz target: settings YAML (ORB-SLAM3 v1.0 keys and the older style) and --set values: the
// first part (before "\n===\n") is the settings file, every line of the second part one --set
// KEY=VALUE; the result is resolved against every declared key (ResolveSettings).
#include "detslam/io/settings.h"
#include "detslam/pipeline/settings_keys.h"
#include "fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace detslam;
  const std::vector<std::string> parts = fuzz::SplitParts(fuzz::Bytes(data, size));
  const std::string path = fuzz::WriteInput("settings.yaml", parts[0]);
  Settings settings;
  if (!fuzz::Accepts([&] { settings = ReadSettings(path); })) return 0;
  std::vector<std::string> overrides;
  if (parts.size() > 1) {
    std::string line;
    for (const char c : parts[1]) {
      if (c == '\n') {
        overrides.push_back(line);
        line.clear();
      } else {
        line += c;
      }
    }
    if (!line.empty()) overrides.push_back(line);
  }
  if (!fuzz::Accepts([&] { ApplySettingOverrides(overrides, &settings); })) return 0;
  fuzz::Accepts([&] { ResolveSettings(settings); });
  return 0;
}
