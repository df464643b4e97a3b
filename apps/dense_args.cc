#include "dense_args.h"

#include <unistd.h>

#include <cstdio>

namespace detslam::app {

void AddDenseOptions(CLI::App* cmd, TsdfOptions* o) {
  cmd->add_option("--voxel-size", o->voxel_m, "Dense map: voxel edge in metres")->capture_default_str();
  cmd->add_option("--truncation", o->truncation_m, "Dense map: TSDF truncation distance in metres")
      ->capture_default_str();
  cmd->add_option("--dense-max-depth", o->max_depth_m, "Dense map: depth beyond this (metres) is not fused")
      ->capture_default_str();
  cmd->add_option("--dense-min-weight", o->min_weight,
                  "Dense map: a surface needs this many keyframe observations to be written")
      ->capture_default_str();
  cmd->add_flag("--no-carve", [o](int64_t) { o->carve = false; },
                "Dense map: do not clear free space in front of later depth (a surface fused once stays)");
}

void DenseProgress(size_t done, size_t total, bool enabled) {
  if (!enabled) return;
  if (!isatty(fileno(stderr))) {
    if (done % 50 == 0 || done == total)
      std::fprintf(stderr, "[dense] %zu/%zu keyframes fused\n", done, total);
    return;
  }
  std::fprintf(stderr, "\r[dense] %zu/%zu keyframes fused", done, total);
  if (done == total) std::fprintf(stderr, "\n");
  std::fflush(stderr);
}

void PrintDenseSummary(const std::string& path, const DenseMapStats& s, size_t masked,
                       bool segmented) {
  std::printf("dense map: %s, %zu points from %zu keyframes (%zu with dynamic pixels removed), "
              "%zu voxel blocks (%.0f MB), fusion %.1f s, extraction %.1f s\n",
              path.c_str(), s.points, s.keyframes, masked, s.blocks, s.memory_mb, s.fusion_s,
              s.extraction_s);
  if (!segmented)
    std::printf("note: no dynamic masks used: moving people, if any, are fused into the dense map\n");
  if (s.unreadable > 0) std::printf("note: %zu keyframes could not be read (skipped)\n", s.unreadable);
  if (s.not_in_source > 0)
    std::printf("note: %zu keyframes are not frames of this source (a loaded map's): left out\n",
                s.not_in_source);
}

}  // namespace detslam::app
