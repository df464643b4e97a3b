// `detslam report`: a self-contained HTML page (inline SVG, no scripts, no external files) of one
// `detslam run` output folder: a summary of the run, its accuracy against ground truth when given
// (the figure of `detslam eval --plot`), and per-frame plots of tracking, the dynamic-object
// filter and the stage timings.
#pragma once

#include <string>

#include "detslam/eval/evaluate.h"
#include "detslam/eval/run_log.h"

namespace detslam {

// Per-frame figure over the frame index: (a) tracking inliers and keypoints, frames without pose
// shaded, keyframes ticked, loop closures marked; (b) keypoints rejected by the dynamic filter and
// by the geometric check, with the number of dynamic objects; (c) per-stage time per frame.
std::string RenderRunSvg(const RunLog& run);

// The HTML page; `eval` may be null (no ground truth: no accuracy section).
std::string RenderHtmlReport(const RunLog& run, const EvalResult* eval);

// Writes RenderHtmlReport atomically to `path`.
void WriteHtmlReport(const std::string& path, const RunLog& run, const EvalResult* eval);

}  // namespace detslam
