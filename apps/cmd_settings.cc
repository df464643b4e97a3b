// detslam settings: lists detslam's own settings keys (name, type, default, range, help) and, with
// --config / --dataset / --set, the value each key takes for that configuration.
#include <algorithm>
#include <cstdio>
#include <memory>

#include "commands.h"
#include "detslam/io/settings.h"
#include "detslam/pipeline/settings_keys.h"

namespace detslam::app {
namespace {

struct SettingsArgs {
  bool list = false;
  std::string config;
  std::string dataset;
  std::vector<std::string> overrides;  // --set KEY=VALUE
};

void PrintSettings(const SettingsArgs& a) {
  const std::vector<SettingSpec>& specs = DeclaredSettings();
  const bool effective = !a.config.empty() || !a.dataset.empty() || !a.overrides.empty();
  std::vector<std::pair<std::string, SettingValue>> values;
  if (effective) {
    Settings settings;
    if (!a.config.empty()) {
      settings = ReadSettings(a.config);
    } else if (!a.dataset.empty()) {
      settings = PresetForDataset(a.dataset);
    } else {
      settings.source = "defaults";
    }
    ApplySettingOverrides(a.overrides, &settings);
    values = SettingValues(ResolveSettings(settings));
    std::printf("settings: %s\n", settings.source.c_str());
  }
  size_t width = 0;
  for (const SettingSpec& s : specs) width = std::max(width, s.key.size());
  for (size_t i = 0; i < specs.size(); ++i) {
    const SettingSpec& s = specs[i];
    std::printf("%-*s  %-6s  default %s", static_cast<int>(width), s.key.c_str(), ToString(s.type),
                FormatSettingValue(s.default_value).empty()
                    ? "\"\""
                    : FormatSettingValue(s.default_value).c_str());
    const std::string range = FormatSettingRange(s);
    if (!range.empty()) std::printf("  range %s", range.c_str());
    if (effective) {
      const std::string v = FormatSettingValue(values[i].second);
      std::printf("  value %s", v.empty() ? "\"\"" : v.c_str());
    }
    std::printf("\n%*s  %s\n", static_cast<int>(width), "", s.help.c_str());
  }
  std::printf(
      "\nSettings files are ORB-SLAM3 YAML; an undeclared key in detslam's namespaces (Tracking., "
      "LocalMapping., "
      "LoopClosing., Dynamic., Segmentation.) or in --set is an error, other keys (Viewer.*, "
      "System.*, ...) are ignored.\n");
}

}  // namespace

void AddSettingsCommand(CLI::App& app) {
  auto a = std::make_shared<SettingsArgs>();
  auto* cmd = app.add_subcommand("settings",
                                 "List detslam's settings keys with type, default, range and help");
  cmd->add_flag("--list", a->list, "List every key (the default action)");
  cmd->add_option("--config", a->config, "Also print each key's value with this settings YAML");
  cmd->add_option("--dataset", a->dataset,
                  "Also print each key's value with this folder's settings or preset");
  cmd->add_option("--set", a->overrides,
                  "Override a key, KEY=VALUE (repeatable), as for detslam run");
  cmd->callback([a] { PrintSettings(*a); });
}

}  // namespace detslam::app
