// A run's output files: trajectory.txt (main map), trajectory_map<N>.txt (maps that never merged),
// keyframes.txt, map.ply, the map file (--save-map), keyframe_masks/ and the dense map
// (--dense-map), and run.json, all written atomically.
#pragma once

#include "detslam/dense/dense_fusion.h"
#include "detslam/pipeline/runner.h"

namespace detslam {

// Writes every output of a finished (or interrupted) run into options.out_dir and fills the
// summary's output counts (frames in the main map, maps left, map file size, keyframe masks,
// dense map). `masks`: the keyframes' Det-SLAM masks (KeyframeMaskRecorder); `segmented`: a
// segmenter ran. Throws InputError naming a file that cannot be written.
void WriteRunOutputs(const RgbdSource& dataset, const Settings& settings, const RunOptions& options,
                     const SlamSystem& slam, const KeyframeMasks& masks, bool segmented,
                     RunSummary& summary);

}  // namespace detslam
