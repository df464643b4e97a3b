// Evaluation results as JSON (machine-readable, for `detslam report` and scripts) and as text
// (the summary `detslam eval` prints, laid out like evo / evaluate_*.py --verbose).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "detslam/eval/evaluate.h"

namespace detslam {

// Keys: inputs, options, poses, ate {pairs, alignment, rmse_m...}, rpe {delta, unit, pairs,
// trans_m, rot_deg, trans_m_per_s, rot_deg_per_s}, coverage {...}; with `with_series`, also the
// per-pair series (ate.series: [t, err], rpe.series: [t_from, trans, rot]) in seconds.
nlohmann::json EvalResultToJson(const EvalResult& result, bool with_series);

// Writes EvalResultToJson(result, true) atomically (pretty-printed).
void WriteEvalJson(const std::string& path, const EvalResult& result);

// Multi-line human-readable summary ending in a newline.
std::string FormatEvalText(const EvalResult& result);

}  // namespace detslam
