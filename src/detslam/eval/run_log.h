// What `detslam report` reads back from a `detslam run` output folder: from run.json (written by
// pipeline/runner.cc) the dataset, settings source, mode, segmenter, counts, wall time and the
// per-frame log with its stage timings and maps, the atlas summary ("maps"); the summary "timings"
// and the other keys are not read.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace detslam {

struct RunFrameLog {
  int64_t index = 0;
  double stamp = 0;      // colour image stamp (seconds)
  std::string state;     // tracking state after the frame ("ok", "lost", ...)
  bool tracked = false;  // the frame has a pose
  std::string method;    // how it was tracked ("motion", "reference", ...)
  int inliers = 0;       // landmark inliers after local-map tracking (and the geometric check)
  bool keyframe = false;
  bool loop_closed = false;
  int keypoints = 0;           // keypoints left for tracking (after the dynamic filter)
  int dynamic_instances = 0;   // instances the dynamic filter used (dynamic class, score >= min)
  int rejected_keypoints = 0;  // keypoints the dynamic filter rejected
  int geometric_rejected = 0;  // keypoints the geometric check labelled
  double segmentation_ms = 0, extraction_ms = 0, tracking_ms = 0, mapping_ms = 0;
  int map = -1;        // map of the atlas it was tracked in (-1: no pose, or an older run log)
  int final_map = -1;  // map that holds it at the end (maps merged count as the one they joined)
  int map_keyframes = -1, map_points = -1;  // atlas size after the frame (-1: an older run log)
};

// Several maps (run.json "maps"; absent in older run logs: main -1).
struct RunMapsLog {
  int main = -1;            // the map of trajectory.txt
  int started = 0, merged = 0, left = 0;
  int64_t frames_in_main = 0;             // frames in trajectory.txt
  std::vector<int64_t> merge_frames;      // input frame of each merge
};

// Camera-rate mode (run.json "realtime"; absent for other runs: offered 0).
struct RunRealtimeLog {
  int64_t offered = 0, dropped = 0;
  double processed_fps = 0;
  double latency_median_ms = 0, latency_p99_ms = 0, latency_max_ms = 0;
  // Asynchronous segmentation (absent in older files and with --sync-segmentation: false).
  bool asynchronous = false;
  int64_t frames_segmented = 0, keyframes_deferred = 0;
  int64_t keyframes_stale_masks = 0;  // made with stale masks after waiting for fresh ones
  double mask_age_median = 0, mask_age_max = 0;  // input frames
  // Keyframes mapped without fusion / BA because more were waiting (absent in older files: -1).
  int64_t keyframes_mapped_in_burst = -1;
};

struct RunLog {
  std::string path;  // the run.json read
  std::string dataset, settings, mode, segmenter;
  int64_t frames = 0, frames_tracked = 0, keyframes = 0, map_points = 0;
  int64_t relocalizations = 0, loops_closed = 0;
  double wall_s = 0;
  RunMapsLog maps;
  RunRealtimeLog realtime;
  std::vector<RunFrameLog> per_frame;

  double TrackedFraction() const {
    return frames > 0 ? static_cast<double>(frames_tracked) / frames : 0.0;
  }
  double FramesPerSecond() const { return wall_s > 0 ? frames / wall_s : 0.0; }
};

// Reads run.json. Throws InputError naming the file (and the line of a JSON syntax error, or the
// missing or mistyped key).
RunLog ReadRunLog(const std::string& path);

}  // namespace detslam
