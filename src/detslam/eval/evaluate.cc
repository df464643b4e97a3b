#include "detslam/eval/evaluate.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "detslam/core/check.h"
#include "detslam/io/text_lines.h"

namespace detslam {

bool EvalOptions::Check(std::string* error) const {
  if (!(max_difference_s > 0.0) || !std::isfinite(max_difference_s)) {
    *error = "max difference must be a positive number of seconds";
    return false;
  }
  if (!std::isfinite(offset_s)) {
    *error = "offset must be finite";
    return false;
  }
  RpeOptions rpe{rpe_delta, rpe_unit, offset_s};
  return rpe.Check(error);
}

EvalResult Evaluate(const Trajectory& gt, const Trajectory& est,
                    const std::vector<Timestamp>& frame_stamps, const EvalOptions& options) {
  std::string why;
  DETSLAM_CHECK_MSG(options.Check(&why), why);
  EvalResult r;
  r.options = options;
  r.gt_poses = gt.size();
  r.est_poses = est.size();
  AteOptions ate;
  ate.association.max_difference_s = options.max_difference_s;
  ate.association.offset_s = options.offset_s;
  ate.with_scale = options.with_scale;
  r.ate = ComputeAte(gt, est, ate);
  r.rpe = ComputeRpe(gt, est, RpeOptions{options.rpe_delta, options.rpe_unit, options.offset_s});

  std::vector<Timestamp> gt_stamps, est_stamps;
  for (const StampedPose& p : gt) gt_stamps.push_back(p.stamp);
  for (const StampedPose& p : est) est_stamps.push_back(p.stamp);
  AssociationOptions assoc{options.max_difference_s, options.offset_s};
  if (frame_stamps.empty()) {
    // Frames are the ground-truth stamps themselves: they live on the ground-truth clock, so the
    // estimate's offset applies in the frame<->estimate matching instead; shift the frames back.
    std::vector<Timestamp> frames;
    const int64_t offset_ns = static_cast<int64_t>(std::llround(options.offset_s * 1e9));
    for (Timestamp t : gt_stamps) frames.push_back(Timestamp{t.ns - offset_ns});
    r.coverage = ComputeCoverage(frames, gt_stamps, est_stamps, assoc);
  } else {
    r.coverage = ComputeCoverage(frame_stamps, gt_stamps, est_stamps, assoc);
  }
  return r;
}

Trajectory SortTrajectory(Trajectory trajectory, const std::string& path) {
  std::stable_sort(trajectory.begin(), trajectory.end(),
                   [](const StampedPose& a, const StampedPose& b) { return a.stamp < b.stamp; });
  for (size_t i = 1; i < trajectory.size(); ++i) {
    if (trajectory[i].stamp == trajectory[i - 1].stamp) {
      throw InputError(path, 0, "duplicate timestamp " + trajectory[i].stamp.ToString());
    }
  }
  return trajectory;
}

std::vector<Timestamp> ReadFrameStamps(const std::string& path, std::string* resolved_path) {
  std::string file = path;
  if (std::filesystem::is_directory(path)) file = (std::filesystem::path(path) / "rgb.txt").string();
  if (!std::filesystem::is_regular_file(file)) throw InputError(file, 0, "frame list not found");
  if (resolved_path != nullptr) *resolved_path = file;
  std::vector<Timestamp> stamps;
  ForEachDataLine(file, [&](int line, const std::vector<std::string>& fields) {
    Timestamp t;
    if (fields.empty() || !ParseTimestamp(fields[0], &t)) {
      throw InputError(file, line, "malformed timestamp '" + (fields.empty() ? "" : fields[0]) + "'");
    }
    stamps.push_back(t);
  });
  if (stamps.empty()) throw InputError(file, 0, "no frames listed");
  return stamps;
}

EvalResult EvaluateFiles(const std::string& gt_path, const std::string& est_path,
                         const std::string& frames, const EvalOptions& options) {
  std::string why;
  if (!options.Check(&why)) throw InputError("eval options: " + why);
  const Trajectory gt = SortTrajectory(ReadTumTrajectory(gt_path), gt_path);
  const Trajectory est = SortTrajectory(ReadTumTrajectory(est_path), est_path);
  if (gt.size() < 2) throw InputError(gt_path, 0, "ground truth needs at least 2 poses");
  std::string frames_file;
  std::vector<Timestamp> frame_stamps;
  if (!frames.empty()) frame_stamps = ReadFrameStamps(frames, &frames_file);
  EvalResult r;
  try {
    r = Evaluate(gt, est, frame_stamps, options);
  } catch (const InputError& e) {
    throw InputError(est_path, 0, std::string(e.what()) + " (ground truth: " + gt_path + ")");
  }
  r.gt_path = gt_path;
  r.est_path = est_path;
  r.frames_path = frames_file;
  return r;
}

}  // namespace detslam
