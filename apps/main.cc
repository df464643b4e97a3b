// The `detslam` command: subcommands run, eval, synth, segment, report, settings, vocab (--help).
#include <spdlog/spdlog.h>

#include <csignal>
#include <exception>
#include <iostream>

#include "commands.h"
#include "detslam/core/check.h"

int main(int argc, char** argv) {
  // A write beyond the file size limit (ulimit -f) then fails with an error the atomic writes
  // report ("disk full?") instead of killing the process.
  std::signal(SIGXFSZ, SIG_IGN);
  CLI::App app{"detslam: RGB-D SLAM for dynamic scenes (Det-SLAM method)"};
  app.require_subcommand(1);
  bool verbose = false;
  app.add_flag("-v,--verbose", verbose, "Debug logging");
  app.parse_complete_callback([&] {
    spdlog::set_level(verbose ? spdlog::level::debug : spdlog::level::info);
  });
  detslam::app::AddRunCommand(app);
  detslam::app::AddEvalCommand(app);
  detslam::app::AddSynthCommand(app);
  detslam::app::AddSegmentCommand(app);
  detslam::app::AddReportCommand(app);
  detslam::app::AddSettingsCommand(app);
  detslam::app::AddVocabCommand(app);
  detslam::app::AddMapCommand(app);
  detslam::app::AddRosbagCommand(app);
  detslam::app::AddDensifyCommand(app);
  detslam::app::AddViewCommand(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const detslam::InputError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  } catch (const detslam::app::CommandFailed& e) {
    std::cerr << "error: " << e.what() << "\n";
    return e.code;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
