// detslam run: placeholder until the run module lands (exits 2 and says so).
#include "commands.h"

namespace detslam::app {

void AddRunCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("run", "(not implemented yet)");
  cmd->allow_extras();
  cmd->callback([] { throw CommandFailed("'detslam run' is not implemented yet", 2); });
}

}  // namespace detslam::app
