#include "detslam/eval/run_log.h"

#include <algorithm>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>

#include "detslam/core/check.h"

namespace detslam {
namespace {

using nlohmann::json;

// Value of `key` in `j` as T; a missing or mistyped key is an InputError naming `where`.
template <typename T>
T Get(const json& j, const char* key, const std::string& path, const std::string& where) {
  const auto it = j.find(key);
  if (it == j.end()) throw InputError(path, 0, where + "missing key '" + key + "'");
  try {
    return it->get<T>();
  } catch (const json::exception&) {
    throw InputError(path, 0, where + "key '" + key + "' has the wrong type");
  }
}

}  // namespace

RunLog ReadRunLog(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw InputError(path, 0, "cannot open run log (run.json of a `detslam run` output folder)");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  json j;
  try {
    j = json::parse(text);
  } catch (const json::parse_error& e) {
    const size_t at = std::min(e.byte, text.size());
    const int line = 1 + static_cast<int>(std::count(
                             text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
    throw InputError(path, line, std::string("not valid JSON: ") + e.what());
  } catch (const json::exception& e) {  // e.g. a number too large for any type (out_of_range)
    throw InputError(path, 0, std::string("not valid JSON: ") + e.what());
  }
  if (!j.is_object()) throw InputError(path, 0, "run log must be a JSON object");
  RunLog r;
  r.path = path;
  r.dataset = Get<std::string>(j, "dataset", path, "");
  r.settings = Get<std::string>(j, "settings", path, "");
  r.mode = Get<std::string>(j, "mode", path, "");
  r.segmenter = Get<std::string>(j, "segmenter", path, "");
  r.frames = Get<int64_t>(j, "frames", path, "");
  r.frames_tracked = Get<int64_t>(j, "frames_tracked", path, "");
  r.keyframes = Get<int64_t>(j, "keyframes", path, "");
  r.map_points = Get<int64_t>(j, "map_points", path, "");
  r.relocalizations = Get<int64_t>(j, "relocalizations", path, "");
  r.loops_closed = Get<int64_t>(j, "loops_closed", path, "");
  r.wall_s = Get<double>(j, "wall_s", path, "");
  if (j.contains("maps")) {  // written since several maps; older run logs have none
    const json& m = j["maps"];
    r.maps.main = Get<int>(m, "main", path, "maps: ");
    r.maps.started = Get<int>(m, "started", path, "maps: ");
    r.maps.merged = Get<int>(m, "merged", path, "maps: ");
    r.maps.left = Get<int>(m, "left", path, "maps: ");
    r.maps.frames_in_main = Get<int64_t>(j, "frames_in_main_map", path, "");
    const json merges = Get<json>(m, "merges", path, "maps: ");
    if (!merges.is_array()) throw InputError(path, 0, "key 'maps.merges' must be an array");
    for (const json& x : merges) r.maps.merge_frames.push_back(Get<int64_t>(x, "frame", path, "maps.merges: "));
  }
  if (j.contains("realtime")) {  // camera-rate runs only
    const json& t = j["realtime"];
    r.realtime.offered = Get<int64_t>(t, "offered", path, "realtime: ");
    r.realtime.dropped = Get<int64_t>(t, "dropped", path, "realtime: ");
    r.realtime.processed_fps = Get<double>(t, "processed_fps", path, "realtime: ");
    const json latency = Get<json>(t, "latency_ms", path, "realtime: ");
    r.realtime.latency_median_ms = Get<double>(latency, "median", path, "realtime.latency_ms: ");
    r.realtime.latency_p99_ms = Get<double>(latency, "p99", path, "realtime.latency_ms: ");
    r.realtime.latency_max_ms = Get<double>(latency, "max", path, "realtime.latency_ms: ");
    if (t.contains("keyframes_mapped_in_burst")) {
      r.realtime.keyframes_mapped_in_burst =
          Get<int64_t>(t, "keyframes_mapped_in_burst", path, "realtime: ");
    }
    if (t.contains("asynchronous_segmentation")) {
      r.realtime.asynchronous = Get<bool>(t, "asynchronous_segmentation", path, "realtime: ");
    }
    if (r.realtime.asynchronous) {
      r.realtime.frames_segmented = Get<int64_t>(t, "frames_segmented", path, "realtime: ");
      r.realtime.keyframes_deferred = Get<int64_t>(t, "keyframes_deferred", path, "realtime: ");
      if (t.contains("keyframes_stale_masks")) {  // absent before Segmentation.KeyFrameMaxWait
        r.realtime.keyframes_stale_masks =
            Get<int64_t>(t, "keyframes_stale_masks", path, "realtime: ");
      }
      const json age = Get<json>(t, "mask_age_frames", path, "realtime: ");
      r.realtime.mask_age_median = Get<double>(age, "median", path, "realtime.mask_age_frames: ");
      r.realtime.mask_age_max = Get<double>(age, "max", path, "realtime.mask_age_frames: ");
    }
  }
  const json frames = Get<json>(j, "per_frame", path, "");
  if (!frames.is_array()) throw InputError(path, 0, "key 'per_frame' must be an array");
  for (size_t k = 0; k < frames.size(); ++k) {
    const json& f = frames[k];
    const std::string where = "per_frame[" + std::to_string(k) + "]: ";
    if (!f.is_object()) throw InputError(path, 0, where + "must be an object");
    RunFrameLog l;
    l.index = Get<int64_t>(f, "index", path, where);
    l.stamp = Get<double>(f, "stamp", path, where);
    l.state = Get<std::string>(f, "state", path, where);
    l.tracked = Get<bool>(f, "tracked", path, where);
    l.method = Get<std::string>(f, "method", path, where);
    l.inliers = Get<int>(f, "inliers", path, where);
    l.keyframe = Get<bool>(f, "keyframe", path, where);
    l.loop_closed = Get<bool>(f, "loop_closed", path, where);
    l.keypoints = Get<int>(f, "keypoints", path, where);
    l.dynamic_instances = Get<int>(f, "dynamic_instances", path, where);
    l.rejected_keypoints = Get<int>(f, "rejected_keypoints", path, where);
    l.geometric_rejected = Get<int>(f, "geometric_rejected", path, where);
    l.segmentation_ms = Get<double>(f, "segmentation_ms", path, where);
    l.extraction_ms = Get<double>(f, "extraction_ms", path, where);
    l.tracking_ms = Get<double>(f, "tracking_ms", path, where);
    l.mapping_ms = Get<double>(f, "mapping_ms", path, where);
    if (f.contains("map")) l.map = Get<int>(f, "map", path, where);
    if (f.contains("final_map")) l.final_map = Get<int>(f, "final_map", path, where);
    if (f.contains("map_keyframes")) l.map_keyframes = Get<int>(f, "map_keyframes", path, where);
    if (f.contains("map_points")) l.map_points = Get<int>(f, "map_points", path, where);
    r.per_frame.push_back(std::move(l));
  }
  return r;
}

}  // namespace detslam
