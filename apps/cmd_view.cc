// detslam view RUN_DIR: the viewer's page on a finished run (map, keyframes, trajectory, aligned
// ground truth, counters, and a frame slider over the per-frame log with the images of the
// dataset the run read, when it can still be opened), served until Ctrl-C.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "source_args.h"
#include "stop_signals.h"
#include "detslam/core/check.h"
#include "detslam/viewer/run_view.h"
#include "detslam/viewer/viewer_server.h"

namespace detslam::app {
namespace {

struct ViewArgs {
  std::string run_dir;
  SourceArgs from;
  int port = 0;
  bool no_images = false;
};

void View(ViewArgs a) {
  namespace fs = std::filesystem;
  const fs::path dir(a.run_dir);
  RunViewInputs in;
  in.run_dir = a.run_dir;
  if (!a.no_images) {
    if (a.from.dataset.empty() && a.from.rosbag.empty()) {
      std::ifstream json(dir / "run.json");
      const nlohmann::json run = nlohmann::json::parse(json, nullptr, /*allow_exceptions=*/false);
      const std::string source = run.is_object() ? run.value("dataset", "") : "";
      (fs::path(source).extension() == ".bag" ? a.from.rosbag : a.from.dataset) = source;
    }
    try {
      OpenedSource opened = OpenSource(a.from);
      in.camera = opened.settings.camera;
      if (!opened.source->groundtruth_path().empty()) {
        in.ground_truth = ReadTumTrajectory(opened.source->groundtruth_path());
      }
      in.source = std::move(opened.source);
    } catch (const InputError& e) {
      std::fprintf(stderr, "note: the frames' images are not shown (pass --dataset or --rosbag): %s\n", e.what());
    }
  }
  RunView content(std::move(in));  // throws InputError for a damaged run folder
  ViewerServerOptions so;
  so.port = a.port;
  ViewerServer server(&content, so);
  std::printf("detslam view: %s\nviewer: %s (open it in a browser; Ctrl-C to quit)\n", a.run_dir.c_str(),
              server.url().c_str());
  std::fflush(stdout);
  const StopSignals signals("\ndetslam: viewer closed\n");
  signals.Wait();
}

}  // namespace

void AddViewCommand(CLI::App& app) {
  auto args = std::make_shared<ViewArgs>();
  auto* cmd = app.add_subcommand("view", "Show a finished run in the browser viewer (map, trajectories, frames), until Ctrl-C");
  cmd->add_option("run_dir", args->run_dir, "Output folder of `detslam run`")->required();
  AddSourceOptions(cmd, &args->from);
  cmd->add_option("--port", args->port, "Port on 127.0.0.1 (0: a free one, printed)")
      ->capture_default_str()
      ->check(CLI::Range(0, 65535));
  cmd->add_flag("--no-images", args->no_images, "Do not open the run's dataset (map and trajectories only)");
  cmd->callback([args] { View(*args); });
}

}  // namespace detslam::app
