// A self-contained SVG figure of one evaluation (no scripts, no external fonts or files):
// (a) top view of the ground truth and the aligned estimate, on the two world axes along which the
//     ground truth spreads most, with equal scale on both axes;
// (b) ATE (per-pair translational error, m) over time, with untracked stretches shaded;
// (c) RPE over time: translation (m/s, left axis) and rotation (deg/s, right axis) per window
//     start (per window for the frames unit).
#pragma once

#include <string>

#include "detslam/eval/evaluate.h"

namespace detslam {

// The SVG document as text.
std::string RenderEvalSvg(const EvalResult& result);

// Writes RenderEvalSvg(result) atomically to `path`.
void WriteEvalSvg(const std::string& path, const EvalResult& result);

}  // namespace detslam
