// detslam report: one self-contained HTML page (inline SVG) of a `detslam run` output folder:
// run summary, accuracy against ground truth (when found) and per-frame plots.
#include <spdlog/spdlog.h>

#include <cstdio>
#include <filesystem>
#include <memory>

#include "commands.h"
#include "detslam/core/check.h"
#include "detslam/eval/evaluate.h"
#include "detslam/eval/run_log.h"
#include "detslam/eval/run_report.h"

namespace detslam::app {

namespace {

struct ReportArgs {
  std::string run, gt, frames, out;
  bool no_eval = false;
  EvalOptions options;
};

}  // namespace

void AddReportCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "report", "HTML report (self-contained, inline SVG plots) of a `detslam run` output folder");
  auto args = std::make_shared<ReportArgs>();
  cmd->add_option("--run", args->run,
                  "Output folder of `detslam run` (holds run.json, trajectory.txt)")
      ->required();
  cmd->add_option(
      "--gt", args->gt,
      "Ground truth, TUM format (default: groundtruth.txt of the run's dataset, if any)");
  cmd->add_option("--frames", args->frames,
                  "rgb.txt or dataset folder for the tracked fraction (default: the run's dataset "
                  "when the ground truth is its own)");
  cmd->add_option("--out", args->out, "HTML file to write (default: RUN/report.html)");
  cmd->add_option("--max-dt", args->options.max_difference_s,
                  "Association window in seconds (exclusive)")
      ->capture_default_str();
  cmd->add_flag("--no-eval", args->no_eval, "No accuracy section even where ground truth exists");
  cmd->callback([args] {
    namespace fs = std::filesystem;
    const fs::path run_dir(args->run);
    if (!fs::is_directory(run_dir))
      throw InputError(args->run, 0, "not a folder (expected a `detslam run --out` folder)");
    const RunLog run = ReadRunLog((run_dir / "run.json").string());
    std::string why;
    if (!args->options.Check(&why)) throw InputError("detslam report: " + why);
    std::string gt = args->gt, frames = args->frames;
    if (gt.empty() && !args->no_eval) {
      const fs::path own = fs::path(run.dataset) / "groundtruth.txt";
      if (fs::is_regular_file(own)) {
        gt = own.string();
        if (frames.empty() && fs::is_regular_file(fs::path(run.dataset) / "rgb.txt"))
          frames = run.dataset;
      } else {
        spdlog::info("no ground truth at {} (pass --gt FILE): the report has no accuracy section",
                     own.string());
      }
    }
    std::unique_ptr<EvalResult> eval;
    if (!gt.empty() && !args->no_eval) {
      eval = std::make_unique<EvalResult>(
          EvaluateFiles(gt, (run_dir / "trajectory.txt").string(), frames, args->options));
    }
    const std::string out = args->out.empty() ? (run_dir / "report.html").string() : args->out;
    WriteHtmlReport(out, run, eval.get());
    std::printf("report: %s\n", out.c_str());
  });
}

}  // namespace detslam::app
