// detslam densify RUN_DIR: the dense static map of a finished run, from its keyframes.txt (final
// keyframe poses), its keyframe_masks/ (the pixels the Det-SLAM stage removed) and the frames of
// the dataset or bag it ran on (run.json names it; --dataset/--rosbag override).
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "dense_args.h"
#include "detslam/core/check.h"
#include "detslam/io/trajectory.h"
#include "source_args.h"

namespace detslam::app {
namespace {

struct DensifyArgs {
  std::string run_dir;
  SourceArgs from;
  std::string out;  // default RUN_DIR/dense_map.ply
  bool keep_dynamic = false;
  bool no_progress = false;
  TsdfOptions dense;
};

nlohmann::json ReadRunJson(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path.string(), 0, "cannot read the run's run.json (is this a run folder?)");
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path.string(), 0, std::string("not valid JSON: ") + e.what());
  }
}

void Densify(DensifyArgs a) {
  namespace fs = std::filesystem;
  std::string error;
  if (!a.dense.Check(&error)) throw InputError("dense map options: " + error);
  const fs::path dir(a.run_dir);
  const nlohmann::json run = ReadRunJson(dir / "run.json");
  if (a.from.dataset.empty() && a.from.rosbag.empty()) {
    const std::string source = run.value("dataset", "");
    if (source.empty()) throw InputError((dir / "run.json").string(), 0, "names no dataset: pass --dataset or --rosbag");
    (fs::path(source).extension() == ".bag" ? a.from.rosbag : a.from.dataset) = source;
  }
  OpenedSource opened = OpenSource(a.from);
  const Trajectory keyframes = ReadTumTrajectory((dir / "keyframes.txt").string());
  const KeyframeMasks masks =
      a.keep_dynamic ? KeyframeMasks() : ReadKeyframeMasks((dir / "keyframe_masks").string());
  size_t unmatched = 0;
  const std::vector<DenseKeyframe> matched = MatchKeyframes(*opened.source, keyframes, masks, &unmatched);
  if (matched.empty()) {
    throw InputError((dir / "keyframes.txt").string(), 0,
                     "no keyframe is a frame of " + opened.source->name() + " (another dataset?)");
  }
  const bool segmented = run.value("segmenter", "none") != "none";
  if (segmented && !a.keep_dynamic && masks.empty()) {
    std::printf("note: %s has no keyframe masks: every pixel is fused\n", (dir / "keyframe_masks").c_str());
  }
  const std::string out = a.out.empty() ? (dir / "dense_map.ply").string() : a.out;
  std::printf("detslam densify: %zu keyframes of %s from %s (voxel %.3f m)\n", matched.size(),
              a.run_dir.c_str(), opened.source->name().c_str(), a.dense.voxel_m);
  DenseMapStats stats;
  stats.not_in_source = unmatched;
  const TsdfVolume volume = FuseKeyframes(*opened.source, opened.settings.camera, matched, a.dense, &stats,
                                          [&](size_t d, size_t t) { DenseProgress(d, t, !a.no_progress); });
  WriteDenseMap(volume, out, &stats);
  size_t masked = 0;
  for (const DenseKeyframe& kf : matched) masked += !kf.exclude_png.empty();
  PrintDenseSummary(out, stats, masked, segmented && !a.keep_dynamic);
}

}  // namespace

void AddDensifyCommand(CLI::App& app) {
  auto args = std::make_shared<DensifyArgs>();
  auto* cmd = app.add_subcommand(
      "densify", "Dense static map of a finished run: its keyframes fused at their final poses without the dynamic objects' pixels (TSDF, PLY point cloud)");
  cmd->add_option("run_dir", args->run_dir, "Output folder of `detslam run`")->required();
  AddSourceOptions(cmd, &args->from);
  cmd->add_option("--out", args->out, "PLY file to write (default RUN_DIR/dense_map.ply)");
  cmd->add_flag("--keep-dynamic", args->keep_dynamic,
                "Ignore the keyframe masks: fuse every pixel, people included (for comparison)");
  cmd->add_flag("--no-progress", args->no_progress, "No progress line");
  AddDenseOptions(cmd, &args->dense);
  cmd->callback([args] { Densify(*args); });
}

}  // namespace detslam::app
