#include "detslam/eval/report.h"

#include <cstdio>
#include <sstream>

#include "detslam/core/atomic_file.h"

namespace detslam {

namespace {

nlohmann::json StatsJson(const ErrorStats& s) {
  return {{"count", s.count}, {"rmse", s.rmse}, {"mean", s.mean}, {"median", s.median},
          {"std", s.std},     {"min", s.min},   {"max", s.max}};
}

std::string StatsLine(const char* label, const ErrorStats& s, const char* unit) {
  char buf[256];
  std::snprintf(buf, sizeof(buf),
                "  %-14s rmse %.6f  mean %.6f  median %.6f  std %.6f  min %.6f  max %.6f  (%s)\n",
                label, s.rmse, s.mean, s.median, s.std, s.min, s.max, unit);
  return buf;
}

}  // namespace

nlohmann::json EvalResultToJson(const EvalResult& r, bool with_series) {
  using nlohmann::json;
  json j;
  j["inputs"] = {{"groundtruth", r.gt_path}, {"estimate", r.est_path}, {"frames", r.frames_path}};
  j["options"] = {{"max_difference_s", r.options.max_difference_s},
                  {"offset_s", r.options.offset_s},
                  {"scale", r.options.with_scale},
                  {"rpe_delta", r.options.rpe_delta},
                  {"rpe_unit", RpeDeltaUnitName(r.options.rpe_unit)}};
  j["poses"] = {{"groundtruth", r.gt_poses}, {"estimate", r.est_poses}};

  const Eigen::Quaterniond q = r.ate.gt_from_est.b_from_a.rotation();
  const Eigen::Vector3d t = r.ate.gt_from_est.b_from_a.translation();
  json ate = StatsJson(r.ate.error_m);
  ate["unit"] = "m";
  ate["pairs"] = r.ate.pairs.size();
  ate["alignment"] = {{"type", r.options.with_scale ? "sim3" : "se3"},
                      {"scale", r.ate.gt_from_est.scale},
                      {"translation", {t.x(), t.y(), t.z()}},
                      {"quaternion_xyzw", {q.x(), q.y(), q.z(), q.w()}}};
  if (with_series) {
    json series = json::array();
    for (const AtePair& p : r.ate.pairs) series.push_back({p.est_stamp.Seconds(), p.error_m});
    ate["series"] = series;
  }
  j["ate"] = ate;

  json rpe;
  rpe["delta"] = r.rpe.options.delta;
  rpe["unit"] = RpeDeltaUnitName(r.rpe.options.unit);
  rpe["pairs"] = r.rpe.pairs.size();
  rpe["trans_m"] = StatsJson(r.rpe.trans_m);
  rpe["rot_deg"] = StatsJson(r.rpe.rot_deg);
  if (r.rpe.per_second()) {
    rpe["trans_m_per_s"] = StatsJson(r.rpe.TransPerSecond());
    rpe["rot_deg_per_s"] = StatsJson(r.rpe.RotPerSecond());
  }
  if (with_series) {
    json series = json::array();
    for (const RpePair& p : r.rpe.pairs) series.push_back({p.est_from.Seconds(), p.trans_m, p.rot_deg});
    rpe["series"] = series;
  }
  j["rpe"] = rpe;

  j["coverage"] = {{"frames_with_gt", r.coverage.frames_with_gt},
                   {"frames_tracked", r.coverage.frames_tracked},
                   {"fraction", r.coverage.fraction},
                   {"longest_untracked_frames", r.coverage.longest_untracked_frames},
                   {"longest_untracked_s", r.coverage.longest_untracked_s},
                   {"longest_untracked_start_s", r.coverage.longest_untracked_start.Seconds()}};
  return j;
}

void WriteEvalJson(const std::string& path, const EvalResult& result) {
  const std::string text = EvalResultToJson(result, true).dump(2);
  WriteFileAtomically(path, [&](std::ostream& out) { out << text << "\n"; });
}

std::string FormatEvalText(const EvalResult& r) {
  std::ostringstream os;
  char buf[512];
  if (!r.gt_path.empty()) os << "ground truth: " << r.gt_path << " (" << r.gt_poses << " poses)\n";
  if (!r.est_path.empty()) os << "estimate:     " << r.est_path << " (" << r.est_poses << " poses)\n";
  std::snprintf(buf, sizeof(buf),
                "ATE w.r.t. translation (m), %s alignment%s, association < %.3f s, offset %.3f s\n",
                r.options.with_scale ? "Sim(3)" : "SE(3)",
                r.options.with_scale ? "" : " without scale", r.options.max_difference_s,
                r.options.offset_s);
  os << buf;
  os << "  compared_pose_pairs " << r.ate.pairs.size() << "\n";
  os << StatsLine("ate", r.ate.error_m, "m");
  if (r.options.with_scale) {
    std::snprintf(buf, sizeof(buf), "  scale %.6f\n", r.ate.gt_from_est.scale);
    os << buf;
  }
  std::snprintf(buf, sizeof(buf), "RPE, fixed delta %g %s (TUM evaluate_rpe.py --fixed_delta), %zu pairs\n",
                r.rpe.options.delta, RpeDeltaUnitName(r.rpe.options.unit), r.rpe.pairs.size());
  os << buf;
  if (r.rpe.pairs.empty()) {
    os << "  no pairs: the estimate does not span the delta with ground truth at both ends\n";
  } else if (r.rpe.per_second()) {
    os << StatsLine("rpe trans", r.rpe.TransPerSecond(), "m/s");
    os << StatsLine("rpe rot", r.rpe.RotPerSecond(), "deg/s");
  } else {
    os << StatsLine("rpe trans", r.rpe.trans_m, "m per window");
    os << StatsLine("rpe rot", r.rpe.rot_deg, "deg per window");
  }
  std::snprintf(buf, sizeof(buf),
                "Coverage: %zu of %zu frames with ground truth tracked (%.1f%%); longest untracked "
                "run %.3f s (%zu frames",
                r.coverage.frames_tracked, r.coverage.frames_with_gt, 100.0 * r.coverage.fraction,
                r.coverage.longest_untracked_s, r.coverage.longest_untracked_frames);
  os << buf;
  if (r.coverage.longest_untracked_frames > 0) {
    os << " from " << r.coverage.longest_untracked_start.ToString();
  }
  os << ")" << (r.frames_path.empty() ? " [frames = ground-truth stamps]" : "") << "\n";
  return os.str();
}

}  // namespace detslam
