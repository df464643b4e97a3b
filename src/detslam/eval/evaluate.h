// One evaluation of an estimated trajectory against ground truth: ATE (ate.h), RPE (rpe.h) and
// tracking coverage (coverage.h), with the TUM RGB-D tools' defaults (0.02 s association, rigid
// alignment without scale, RPE over 1 s windows).
#pragma once

#include <string>
#include <vector>

#include "detslam/eval/ate.h"
#include "detslam/eval/coverage.h"
#include "detslam/eval/rpe.h"

namespace detslam {

struct EvalOptions {
  double max_difference_s = 0.02;  // est<->gt and frame association window (seconds, exclusive)
  double offset_s = 0.0;           // added to estimate/frame stamps to get ground-truth time
  bool with_scale = false;         // Sim(3) instead of SE(3) alignment for ATE
  RpeDeltaUnit rpe_unit = RpeDeltaUnit::kSeconds;  // RPE window unit
  double rpe_delta = 1.0;          // RPE window length in rpe_unit

  bool Check(std::string* error) const;
};

struct EvalResult {
  EvalOptions options;
  std::string gt_path, est_path, frames_path;  // inputs (empty when not from files)
  size_t gt_poses = 0;
  size_t est_poses = 0;
  AteResult ate;
  RpeResult rpe;
  CoverageResult coverage;
};

// `frame_stamps` may be empty: coverage is then measured over the ground-truth stamps.
// Trajectories must be sorted and unique (CHECK). Throws InputError (no file) when fewer than 3
// estimated poses associate with ground truth.
EvalResult Evaluate(const Trajectory& gt, const Trajectory& est,
                    const std::vector<Timestamp>& frame_stamps, const EvalOptions& options);

// Reads the files and evaluates. `frames` is an rgb.txt-style list (`stamp filename` per line) or
// a dataset folder containing rgb.txt; empty for none. Throws InputError naming the file (and
// line) on bad input, duplicate stamps, or too few associated poses.
EvalResult EvaluateFiles(const std::string& gt_path, const std::string& est_path,
                         const std::string& frames, const EvalOptions& options);

// Sorts by stamp; throws InputError naming `path` on a duplicate stamp.
Trajectory SortTrajectory(Trajectory trajectory, const std::string& path);

// Stamps of an rgb.txt-style list, or of <dir>/rgb.txt when `path` is a folder. Throws InputError
// naming the file and line on a malformed stamp, and on a missing file.
std::vector<Timestamp> ReadFrameStamps(const std::string& path, std::string* resolved_path);

}  // namespace detslam
