// detslam eval: ATE / RPE / coverage of an estimated TUM trajectory against ground truth, with the
// TUM RGB-D tools' conventions (see src/detslam/eval/ate.h, rpe.h, coverage.h).
#include <spdlog/spdlog.h>

#include <iostream>
#include <memory>

#include "commands.h"
#include "detslam/core/check.h"
#include "detslam/eval/evaluate.h"
#include "detslam/eval/report.h"
#include "detslam/eval/svg_plot.h"

namespace detslam::app {

namespace {

struct EvalArgs {
  std::string gt, est, frames, json, plot;
  EvalOptions options;
  bool per_frame = false;
};

}  // namespace

void AddEvalCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "eval", "ATE (SE(3)-aligned, TUM evaluate_ate.py), RPE (1 s fixed delta, TUM "
              "evaluate_rpe.py) and tracked fraction of an estimate against ground truth");
  auto args = std::make_shared<EvalArgs>();
  cmd->add_option("--gt", args->gt, "Ground truth, TUM format (groundtruth.txt)")->required();
  cmd->add_option("--est", args->est, "Estimated trajectory, TUM format")->required();
  cmd->add_option("--max-dt", args->options.max_difference_s,
                  "Association window in seconds (exclusive)")
      ->capture_default_str();
  cmd->add_option("--offset", args->options.offset_s,
                  "Seconds added to estimate (and frame) stamps to get ground-truth time")
      ->capture_default_str();
  cmd->add_flag("--scale", args->options.with_scale,
                "Sim(3) alignment (estimate scale corrected); RGB-D results use SE(3)");
  cmd->add_option("--frames", args->frames,
                  "rgb.txt or dataset folder: camera frames for the tracked fraction "
                  "(default: the ground-truth stamps)");
  cmd->add_option("--json", args->json, "Write all results (with per-pair series) as JSON");
  cmd->add_option("--plot", args->plot, "Write an SVG figure: top view, ATE and RPE over time");
  cmd->add_flag("--per-frame", args->per_frame,
                "RPE over consecutive estimated poses (delta 1 frame) instead of 1 s");
  cmd->callback([args] {
    if (args->per_frame) {
      args->options.rpe_unit = RpeDeltaUnit::kFrames;
      args->options.rpe_delta = 1;
    }
    std::string why;
    if (!args->options.Check(&why)) throw InputError("detslam eval: " + why);
    const EvalResult result = EvaluateFiles(args->gt, args->est, args->frames, args->options);
    std::cout << FormatEvalText(result) << std::flush;
    if (!args->json.empty()) {
      WriteEvalJson(args->json, result);
      spdlog::info("wrote {}", args->json);
    }
    if (!args->plot.empty()) {
      WriteEvalSvg(args->plot, result);
      spdlog::info("wrote {}", args->plot);
    }
  });
}

}  // namespace detslam::app
