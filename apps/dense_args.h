// The dense-map options and output shared by `detslam run --dense-map` and `detslam densify`.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "detslam/dense/dense_fusion.h"

namespace detslam::app {

// --voxel-size, --truncation, --dense-max-depth, --dense-min-weight, --no-carve.
void AddDenseOptions(CLI::App* cmd, TsdfOptions* options);

// A progress line for the fusion (a bar on a terminal, else every 50 keyframes).
void DenseProgress(size_t done, size_t total, bool enabled);

// What was written: points, keyframes fused and masked, memory, time.
void PrintDenseSummary(const std::string& path, const DenseMapStats& stats, size_t masked,
                       bool segmented);

}  // namespace detslam::app
