// detslam eval: placeholder until the eval module lands (exits 2 and says so).
#include "commands.h"

namespace detslam::app {

void AddEvalCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("eval", "(not implemented yet)");
  cmd->allow_extras();
  cmd->callback([] { throw CommandFailed("'detslam eval' is not implemented yet", 2); });
}

}  // namespace detslam::app
