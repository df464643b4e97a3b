// detslam synth: placeholder until the synth module lands (exits 2 and says so).
#include "commands.h"

namespace detslam::app {

void AddSynthCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("synth", "(not implemented yet)");
  cmd->allow_extras();
  cmd->callback([] { throw CommandFailed("'detslam synth' is not implemented yet", 2); });
}

}  // namespace detslam::app
