#include "detslam/pipeline/runner.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <numeric>

#include "detslam/core/atomic_file.h"
#include "detslam/io/ply.h"

namespace detslam {
namespace {

nlohmann::json StatsJson(const StageStats& s) {
  return {{"median_ms", s.median_ms}, {"mean_ms", s.mean_ms}, {"p90_ms", s.p90_ms}, {"max_ms", s.max_ms}};
}

void WriteOutputs(const RgbdDataset& dataset, const Settings& settings, const RunOptions& options,
                  const SlamSystem& slam, const RunSummary& summary) {
  namespace fs = std::filesystem;
  const fs::path out(options.out_dir);
  const std::string header = "detslam trajectory (world_from_camera) of " + dataset.dir() +
                             "\nsettings: " + settings.source;
  WriteTumTrajectory((out / "trajectory.txt").string(), slam.FrameTrajectory(), header);
  WriteTumTrajectory((out / "keyframes.txt").string(), slam.KeyFrameTrajectory(), "detslam keyframes of " + dataset.dir());
  std::vector<Eigen::Vector3d> points;
  for (const auto& [id, lm] : slam.map().landmarks()) {
    (void)id;
    points.push_back(lm.position);
  }
  WritePointCloudPly((out / "map.ply").string(), points, {});
  nlohmann::json j;
  j["dataset"] = dataset.dir();
  j["settings"] = settings.source;
  j["mode"] = "sequential";
  j["camera"] = {{"fx", settings.camera.fx}, {"fy", settings.camera.fy}, {"cx", settings.camera.cx},
                 {"cy", settings.camera.cy}, {"depth_map_factor", settings.camera.depth_map_factor},
                 {"bf", settings.camera.bf}, {"th_depth", settings.camera.th_depth}};
  j["orb"] = {{"num_features", options.slam.orb.num_features}, {"scale_factor", options.slam.orb.scale_factor},
              {"num_levels", options.slam.orb.num_levels}, {"ini_th_fast", options.slam.orb.ini_th_fast},
              {"min_th_fast", options.slam.orb.min_th_fast}};
  j["seed"] = options.slam.tracker.seed;
  j["frames"] = summary.frames;
  j["frames_tracked"] = summary.tracked;
  j["tracked_fraction"] = summary.TrackedFraction();
  j["keyframes"] = summary.keyframes;
  j["map_points"] = summary.landmarks;
  j["relocalizations"] = summary.relocalizations;
  j["wall_s"] = summary.wall_s;
  j["timings"] = {{"extraction", StatsJson(summary.extraction)}, {"tracking", StatsJson(summary.tracking)},
                  {"local_mapping_per_keyframe", StatsJson(summary.mapping)}, {"total_per_frame", StatsJson(summary.total)}};
  nlohmann::json per_frame = nlohmann::json::array();
  for (const FrameReport& r : summary.reports) {
    per_frame.push_back({{"index", r.index}, {"stamp", r.stamp.Seconds()}, {"state", ToString(r.tracking.state)},
                         {"tracked", r.tracking.pose_valid}, {"method", r.tracking.method},
                         {"inliers", r.tracking.num_inliers}, {"keyframe", r.keyframe},
                         {"keypoints", r.num_keypoints}, {"extraction_ms", r.timings.extraction_ms},
                         {"tracking_ms", r.timings.tracking_ms}, {"mapping_ms", r.timings.mapping_ms}});
  }
  j["per_frame"] = per_frame;
  WriteFileAtomically((out / "run.json").string(), [&](std::ostream& os) { os << j.dump(1) << "\n"; });
}

}  // namespace

SlamOptions SlamOptionsFromSettings(const Settings& settings, uint64_t seed) {
  SlamOptions o;
  o.orb.num_features = settings.orb.n_features;
  o.orb.scale_factor = settings.orb.scale_factor;
  o.orb.num_levels = settings.orb.n_levels;
  o.orb.ini_th_fast = settings.orb.ini_th_fast;
  o.orb.min_th_fast = settings.orb.min_th_fast;
  o.tracker.seed = seed;
  o.tracker.max_frames_between_keyframes = std::max(1, static_cast<int>(std::lround(settings.camera.fps)));
  o.mapper.local_ba = settings.GetBool("LocalMapping.BundleAdjustment", o.mapper.local_ba);
  o.mapper.max_local_keyframes = settings.GetInt("LocalMapping.MaxLocalKeyFrames", o.mapper.max_local_keyframes);
  return o;
}

StageStats ComputeStageStats(std::vector<double> v) {
  StageStats s;
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  s.median_ms = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  s.mean_ms = std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(n);
  s.p90_ms = v[std::min(n - 1, static_cast<size_t>(0.9 * static_cast<double>(n)))];
  s.max_ms = v.back();
  return s;
}

RunSummary RunSequential(const RgbdDataset& dataset, const Settings& settings,
                         const RunOptions& options, const ProgressFn& progress) {
  const auto t_start = std::chrono::steady_clock::now();
  SlamSystem slam(settings.camera, options.slam);
  RunSummary summary;
  size_t n = dataset.size();
  if (options.max_frames >= 0) n = std::min(n, static_cast<size_t>(options.max_frames));
  std::vector<double> ext, trk, map_ms, total;
  for (size_t i = 0; i < n; ++i) {
    const RgbdImages images = dataset.Load(i, settings.camera);
    FrameReport r = slam.ProcessFrame(static_cast<int64_t>(i), dataset.frame(i).rgb_stamp, images.gray, images.depth_m);
    ++summary.frames;
    if (r.tracking.pose_valid) ++summary.tracked;
    if (r.tracking.relocalized) ++summary.relocalizations;
    ext.push_back(r.timings.extraction_ms);
    trk.push_back(r.timings.tracking_ms);
    if (r.keyframe) map_ms.push_back(r.timings.mapping_ms);
    total.push_back(r.timings.extraction_ms + r.timings.tracking_ms + r.timings.mapping_ms);
    summary.reports.push_back(r);
    if (progress) progress(i + 1, n, r);
  }
  summary.keyframes = slam.map().NumKeyFrames();
  summary.landmarks = slam.map().NumLandmarks();
  summary.extraction = ComputeStageStats(ext);
  summary.tracking = ComputeStageStats(trk);
  summary.mapping = ComputeStageStats(map_ms);
  summary.total = ComputeStageStats(total);
  summary.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  WriteOutputs(dataset, settings, options, slam, summary);
  return summary;
}

}  // namespace detslam
