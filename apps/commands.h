// Each `detslam` subcommand lives in its own file (cmd_<name>.cc) and registers itself on the
// top-level CLI11 app through one of these functions. A subcommand's callback reports failure by
// throwing detslam::InputError (bad input; exit 1) or CommandFailed (other non-zero exits).
#pragma once

#include <CLI/CLI.hpp>
#include <stdexcept>
#include <string>

namespace detslam::app {

struct CommandFailed : std::runtime_error {
  CommandFailed(const std::string& message, int exit_code)
      : std::runtime_error(message), code(exit_code) {}
  int code;
};

void AddEvalCommand(CLI::App& app);
void AddSynthCommand(CLI::App& app);
void AddRunCommand(CLI::App& app);
void AddSegmentCommand(CLI::App& app);
void AddReportCommand(CLI::App& app);
void AddSettingsCommand(CLI::App& app);
void AddVocabCommand(CLI::App& app);
void AddMapCommand(CLI::App& app);
void AddRosbagCommand(CLI::App& app);
void AddDensifyCommand(CLI::App& app);
void AddViewCommand(CLI::App& app);

}  // namespace detslam::app
