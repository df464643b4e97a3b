#include "detslam/pipeline/run_outputs.h"

#include <spdlog/spdlog.h>

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>

#include "detslam/core/atomic_file.h"
#include "detslam/io/ply.h"
#include "detslam/pipeline/settings_keys.h"

namespace detslam {
namespace {

// A pose as TUM's order: tx ty tz qx qy qz qw.
nlohmann::json PoseJson(const Rigid3d& pose) {
  const Eigen::Vector3d& t = pose.translation();
  const Eigen::Quaterniond& q = pose.rotation();
  return {t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()};
}

nlohmann::json StatsJson(const ErrorStats& s) {
  return {{"count", s.count}, {"median_ms", s.median}, {"mean_ms", s.mean},
          {"std_ms", s.std},  {"min_ms", s.min},       {"max_ms", s.max}};
}

// The main map's keyframes with their masks; writes the masks (keyframe_masks/) and the dense map
// when asked for (summary.keyframe_masks, summary.dense).
void WriteKeyframeProducts(const RgbdSource& dataset, const Settings& settings,
                           const RunOptions& options, const SlamSystem& slam,
                           const KeyframeMasks& masks, bool segmented, RunSummary& summary) {
  namespace fs = std::filesystem;
  if (!(options.keyframe_masks && segmented) && options.dense_map.empty()) return;
  size_t loaded = 0;  // keyframes of a map loaded from another session (--load-map)
  const std::vector<DenseKeyframe> keyframes =
      MatchKeyframes(dataset, slam.KeyFrameTrajectory(), masks, &loaded);
  if (options.keyframe_masks && segmented) {
    KeyframeMasks kept;
    for (const DenseKeyframe& kf : keyframes) {
      if (!kf.exclude_png.empty()) kept[kf.frame] = kf.exclude_png;
    }
    WriteKeyframeMasks((fs::path(options.out_dir) / "keyframe_masks").string(), kept);
    summary.keyframe_masks = kept.size();
  }
  if (options.dense_map.empty()) return;
  summary.dense.not_in_source = loaded;
  if (loaded > 0) {
    spdlog::warn("dense map: {} keyframes of the loaded map are not frames of {}: left out", loaded,
                 dataset.name());
  }
  const TsdfVolume volume = FuseKeyframes(dataset, settings.camera, keyframes, options.dense,
                                          &summary.dense, options.dense_progress);
  WriteDenseMap(volume, options.dense_map, &summary.dense);
}

}  // namespace

void WriteRunOutputs(const RgbdSource& dataset, const Settings& settings, const RunOptions& options,
                     const SlamSystem& slam, const KeyframeMasks& masks, bool segmented,
                     RunSummary& summary) {
  namespace fs = std::filesystem;
  const fs::path out(options.out_dir);
  const std::string header = "detslam trajectory (world_from_camera) of " + dataset.name() +
                             "\nsettings: " + settings.source;
  // The main map's frames go to trajectory.txt; maps that never merged into it to files of their
  // own (never mixed in). Those of an earlier run in the same folder are removed first.
  const MapTrajectories trajectories = slam.FrameTrajectories();
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(out, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("trajectory_map", 0) == 0 && entry.path().extension() == ".txt")
      fs::remove(entry.path(), ec);
  }
  std::map<double, int> final_map;  // stamp -> map that holds the frame at the end
  summary.tracked_main = 0;
  for (const auto& [map_id, trajectory] : trajectories.by_map) {
    for (const auto& p : trajectory) final_map[p.stamp.Seconds()] = map_id;
    if (map_id == trajectories.main_map) {
      summary.tracked_main = trajectory.size();
      continue;
    }
    WriteTumTrajectory((out / ("trajectory_map" + std::to_string(map_id) + ".txt")).string(),
                       trajectory,
                       header + "\nmap " + std::to_string(map_id) +
                           " of the atlas (never merged into the main map: its own frame)");
  }
  summary.maps_left = static_cast<int>(trajectories.by_map.size());
  WriteTumTrajectory((out / "trajectory.txt").string(),
                     trajectories.main_map < 0 ? Trajectory()
                                               : trajectories.by_map.at(trajectories.main_map),
                     header);
  WriteTumTrajectory((out / "keyframes.txt").string(), slam.KeyFrameTrajectory(),
                     "detslam keyframes of " + dataset.name());
  std::vector<Eigen::Vector3d> points;  // of the main map (the others are in frames of their own)
  {
    const MapStore::ReadAccess map = slam.ReadMap();
    for (const auto& [id, lm] : map->landmarks()) {
      (void)id;
      if (!lm.observations.empty() &&
          map->MapOf(lm.observations.begin()->first) == trajectories.main_map)
        points.push_back(lm.position);
    }
  }
  WritePointCloudPly((out / "map.ply").string(), points, {});
  if (!options.save_map.empty()) summary.map_file_bytes = slam.SaveMap(options.save_map);
  WriteKeyframeProducts(dataset, settings, options, slam, masks, segmented, summary);
  nlohmann::json j;
  j["dataset"] = dataset.name();
  j["settings"] = settings.source;
  j["effective_settings"] = EffectiveSettingsJson(settings, options);
  j["mode"] = !options.threaded        ? "sequential"
              : options.realtime        ? (options.mapping_thread ? "camera rate (mapping thread)"
                                                                  : "camera rate")
              : options.mapping_thread  ? "threaded (mapping thread)"
                                        : "threaded";
  j["camera"] = {{"fx", settings.camera.fx},
                 {"fy", settings.camera.fy},
                 {"cx", settings.camera.cx},
                 {"cy", settings.camera.cy},
                 {"depth_map_factor", settings.camera.depth_map_factor},
                 {"bf", settings.camera.bf},
                 {"th_depth", settings.camera.th_depth},
                 {"disparity_sigma", settings.camera.disparity_sigma}};
  j["orb"] = {{"num_features", options.slam.orb.num_features},
              {"scale_factor", options.slam.orb.scale_factor},
              {"num_levels", options.slam.orb.num_levels},
              {"ini_th_fast", options.slam.orb.ini_th_fast},
              {"min_th_fast", options.slam.orb.min_th_fast}};
  j["seed"] = options.slam.tracker.seed;
  j["interrupted"] = summary.interrupted;
  j["frames"] = summary.frames;
  nlohmann::json skipped = nlohmann::json::array();
  for (const FrameReport& r : summary.reports) {
    if (!r.skipped.empty()) skipped.push_back({{"frame", r.index}, {"reason", r.skipped}});
  }
  j["skipped_frames"] = skipped;
  j["frames_tracked"] = summary.tracked;
  j["tracked_fraction"] = summary.TrackedFraction();
  j["keyframes"] = summary.keyframes;
  j["map_points"] = summary.landmarks;
  j["relocalizations"] = summary.relocalizations;
  j["frames_in_main_map"] = summary.tracked_main;
  nlohmann::json lost = nlohmann::json::array();  // stretches of frames without a pose
  for (size_t i = 0; i < summary.reports.size(); ++i) {
    if (summary.reports[i].tracking.pose_valid) continue;
    size_t k = i;
    while (k + 1 < summary.reports.size() && !summary.reports[k + 1].tracking.pose_valid) ++k;
    lost.push_back({{"first_frame", summary.reports[i].index},
                    {"last_frame", summary.reports[k].index},
                    {"frames", k - i + 1}});
    i = k;
  }
  nlohmann::json merges = nlohmann::json::array();
  for (const LoopRecord& r : summary.loop_records) {
    if (r.merge)
      merges.push_back({{"frame", r.frame}, {"from", r.merged_from}, {"into", r.merged_into}});
  }
  nlohmann::json frames_by_map = nlohmann::json::object();
  for (const auto& [map_id, trajectory] : trajectories.by_map)
    frames_by_map[std::to_string(map_id)] = trajectory.size();
  j["maps"] = {{"main", trajectories.main_map},
               {"started", summary.maps_started},
               {"merged", summary.maps_merged},
               {"left", summary.maps_left},
               {"frames_by_map", frames_by_map},
               {"merges", merges},
               {"lost_stretches", lost}};
  j["loops_closed"] = summary.loops;
  nlohmann::json loops = nlohmann::json::array();
  for (const LoopRecord& r : summary.loop_records) {  // also those of a mapping thread
    loops.push_back({{"frame", r.frame},
                     {"keyframe", r.keyframe},
                     {"candidate_keyframe", r.candidate},
                     {"candidate_frame", r.candidate_frame},
                     {"inliers", r.inliers},
                     {"agreeing_keyframes", r.agreeing},
                     {"correction_m", r.correction_m},
                     {"candidate_from_keyframe", PoseJson(r.candidate_from_keyframe)},
                     {"merge", r.merge},
                     {"welded_keyframes", r.welded_keyframes},
                     {"corrected_after_frame", r.corrected_after_frame},
                     {"map_locked_ms", r.map_locked_ms},
                     {"mapping_wait_ms", r.mapping_wait_ms},
                     {"mapping_held_ms", r.mapping_held_ms}});
  }
  j["loops"] = loops;
  const LoopDetectionStats& ld = summary.loop_detection;
  j["loop_detection"] = {{"candidates", ld.candidates},
                         {"enough_matches", ld.enough_matches},
                         {"rigid_ransac", ld.rigid_ransac},
                         {"verified", ld.verified},
                         {"pending_confirmed", ld.pending_confirmed},
                         {"pending_dropped", ld.pending_dropped},
                         {"revisits", ld.revisits}};
  j["global_ba"] = {{"runs", summary.global_ba_runs},
                    {"stopped", summary.global_ba_stopped},
                    {"applied_after_frames", summary.global_ba_applied_after_frames}};
  if (!options.save_map.empty())
    j["map_file"] = {{"path", options.save_map}, {"bytes", summary.map_file_bytes}};
  if (!options.load_map.empty()) {
    j["loaded_map"] = {{"path", options.load_map},
                       {"keyframes", summary.loaded_keyframes},
                       {"map_points", summary.loaded_landmarks},
                       {"load_ms", summary.map_load_ms},
                       {"localization", options.slam.localization}};
  }
  if (segmented && options.keyframe_masks) j["keyframe_masks"] = summary.keyframe_masks;
  if (!options.dense_map.empty()) {
    const DenseMapStats& d = summary.dense;
    j["dense_map"] = {{"path", options.dense_map},
                      {"voxel_m", options.dense.voxel_m},
                      {"truncation_m", options.dense.truncation_m},
                      {"depth_range_m", {options.dense.min_depth_m, options.dense.max_depth_m}},
                      {"min_weight", options.dense.min_weight},
                      {"carve", options.dense.carve},
                      {"keyframes_fused", d.keyframes},
                      {"keyframes_unreadable", d.unreadable},
                      {"keyframes_not_in_source", d.not_in_source},
                      {"keyframes_masked", summary.keyframe_masks},
                      {"points", d.points},
                      {"blocks", d.blocks},
                      {"memory_mb", d.memory_mb},
                      {"fusion_s", d.fusion_s},
                      {"extraction_s", d.extraction_s}};
  }
  j["vocabulary"] = slam.vocabulary_path();
  j["wall_s"] = summary.wall_s;
  if (options.realtime) {
    const size_t dropped = summary.dropped_frames.size();
    j["realtime"] = {
        {"offered", summary.offered},
        {"dropped", dropped},
        {"dropped_fraction", summary.offered ? static_cast<double>(dropped) / summary.offered : 0.0},
        {"dropped_frames", summary.dropped_frames},
        {"processed_fps", summary.ProcessedFps()},
        {"camera_s", summary.camera_s},
        {"latency_ms",
         {{"median", summary.latency.median},
          {"mean", summary.latency.mean},
          {"p99", summary.latency_p99_ms},
          {"max", summary.latency.max}}},
        {"asynchronous_segmentation", summary.async_segmentation},
        {"keyframes_mapped_in_burst", summary.keyframes_mapped_in_burst}};
    if (summary.async_segmentation) {
      j["realtime"]["frames_segmented"] = summary.frames_segmented;
      j["realtime"]["segmentation_headroom_wait_ms"] = summary.headroom_wait_ms;
      j["realtime"]["mask_age_frames"] = {{"median", summary.mask_age.median},
                                          {"mean", summary.mask_age.mean},
                                          {"max", summary.mask_age.max}};
      j["realtime"]["keyframes_deferred"] = summary.keyframes_deferred;
      j["realtime"]["keyframes_stale_masks"] = summary.keyframes_stale_masks;
      j["realtime"]["keyframes_cleaned"] = summary.keyframes_cleaned;
      j["realtime"]["keypoints_cleaned"] = summary.keypoints_cleaned;
    }
  }
  if (!options.realtime && summary.async_segmentation) {
    j["simulated_async_segmentation"] = {
        {"detector_frames", options.simulated_detector_frames},
        {"frames_segmented", summary.frames_segmented},
        {"mask_age_frames",
         {{"median", summary.mask_age.median},
          {"mean", summary.mask_age.mean},
          {"max", summary.mask_age.max}}},
        {"keyframes_deferred", summary.keyframes_deferred},
        {"keyframes_stale_masks", summary.keyframes_stale_masks},
        {"keyframes_cleaned", summary.keyframes_cleaned},
        {"keypoints_cleaned", summary.keypoints_cleaned}};
  }
  j["segmenter"] = summary.segmenter.empty() ? "none" : summary.segmenter;
  const DetSlamOptions& dyn = options.slam.dynamic;
  j["dynamic_filter"] = {{"classes", dyn.filter.dynamic_classes},
                         {"alpha", dyn.filter.alpha},
                         {"depth_step", dyn.filter.depth_step},
                         {"mask_dilation_px", dyn.filter.mask_dilation_px},
                         {"premask", dyn.premask},
                         {"memory_frames", dyn.memory_frames},
                         {"depth_track_frames", dyn.depth_track_frames},
                         {"geometric_check", dyn.geometric.enabled},
                         {"geometric_coherence", dyn.geometric.coherence},
                         {"geometric_region_frames", summary.async_segmentation
                                                         ? options.camera_rate_region_frames
                                                         : dyn.geometric.region_frames},
                         {"segment_every", dyn.segment_every},
                         {"flow_scale", dyn.propagation.flow_scale},
                         {"keyframe_max_mask_age", dyn.keyframe_max_mask_age},
                         {"keyframe_max_wait", dyn.keyframe_max_wait},
                         {"keyframe_defer_min_inliers", dyn.keyframe_defer_min_inliers},
                         {"keyframe_clean_own_masks", dyn.keyframe_clean_own_masks}};
  j["timings"] = {{"segmentation", StatsJson(summary.segmentation)},
                  {"extraction", StatsJson(summary.extraction)},
                  {"tracking", StatsJson(summary.tracking)},
                  {"local_mapping_per_keyframe", StatsJson(summary.mapping)},
                  {"loop_closing_per_keyframe", StatsJson(summary.loop_closing)},
                  {"total_per_frame", StatsJson(summary.total)}};
  j["loop_closing_thread"] = summary.loop_thread;
  nlohmann::json per_frame = nlohmann::json::array();
  for (const FrameReport& r : summary.reports) {
    auto fm = final_map.find(r.stamp.Seconds());
    per_frame.push_back({{"index", r.index},
                         {"map", r.map_id},  // when tracked
                         {"final_map", r.tracking.pose_valid && fm != final_map.end() ? fm->second
                                                                                      : -1},
                         {"stamp", r.stamp.Seconds()},
                         {"state", r.skipped.empty() ? ToString(r.tracking.state) : "skipped"},
                         {"tracked", r.tracking.pose_valid},
                         {"method", r.tracking.method},
                         {"inliers", r.tracking.num_inliers},
                         {"keyframe", r.keyframe},
                         {"loop_closed", r.loop_closed},
                         {"keypoints", r.num_keypoints},
                         {"map_keyframes", r.map_keyframes},
                         {"map_points", r.map_points},
                         {"dynamic_instances", r.dynamic_instances},
                         {"rejected_keypoints", r.rejected_keypoints},
                         {"geometric_rejected", r.tracking.geometric_rejected},
                         {"segmentation_ms", r.segmentation_ms},
                         {"extraction_ms", r.timings.extraction_ms},
                         {"tracking_ms", r.timings.tracking_ms},
                         {"map_wait_ms", r.timings.map_wait_ms},
                         {"tracking_cpu_ms", r.timings.tracking_cpu_ms},
                         {"mapping_ms", r.timings.mapping_ms}});
    if (r.latency_ms >= 0) per_frame.back()["latency_ms"] = r.latency_ms;
    if (r.mask_age >= 0) {
      per_frame.back()["mask_source"] = r.mask_source;
      per_frame.back()["mask_age"] = r.mask_age;
    }
    if (r.keyframe_deferred) per_frame.back()["keyframe_deferred"] = true;
    if (r.keyframe_stale_masks) per_frame.back()["keyframe_stale_masks"] = true;
    if (r.keyframe_cleaned >= 0) per_frame.back()["keyframe_cleaned_keypoints"] = r.keyframe_cleaned;
  }
  j["per_frame"] = per_frame;
  WriteFileAtomically((out / "run.json").string(),
                      [&](std::ostream& os) { os << j.dump(1) << "\n"; });
}

}  // namespace detslam
