#include "detslam/pipeline/settings_keys.h"

#include <spdlog/spdlog.h>

#include <cstdio>
#include <cstdlib>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <type_traits>

#include "detslam/core/check.h"

namespace detslam {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// ---- typed field <-> SettingValue ----

template <typename T>
constexpr SettingType TypeOf() {
  if constexpr (std::is_same_v<T, bool>) return SettingType::kBool;
  if constexpr (std::is_same_v<T, int>) return SettingType::kInt;
  if constexpr (std::is_floating_point_v<T>) return SettingType::kDouble;
  if constexpr (std::is_same_v<T, std::string>) return SettingType::kString;
  if constexpr (std::is_same_v<T, std::vector<std::string>>) return SettingType::kList;
}

// A float field as the double its text names (0.35f -> 0.35, not 0.3499999940395355).
double FloatAsDouble(float f) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.7g", f);
  return std::strtod(buf, nullptr);
}

template <typename T>
SettingValue ToValue(const T& field) {
  if constexpr (std::is_same_v<T, float>) {
    return FloatAsDouble(field);
  } else {
    return field;
  }
}

template <typename T>
void FromValue(const SettingValue& value, T* field) {
  if constexpr (std::is_same_v<T, float>) {
    *field = static_cast<float>(std::get<double>(value));
  } else {
    *field = std::get<T>(value);
  }
}

// A declared key bound to the field(s) it fills. `field` is a generic lambda
// `[](auto& r) -> auto& { return r.some.field; }` over ResolvedSettings.
struct Binding {
  SettingSpec spec;  // default_value filled by DeclaredSettings()
  std::function<SettingValue(const ResolvedSettings&)> get;
  std::function<void(const SettingValue&, ResolvedSettings*)> set;

  // The key also fills `field` (same type as the first).
  template <typename F>
  Binding Also(F field) && {
    set = [prev = set, field](const SettingValue& v, ResolvedSettings* r) {
      prev(v, r);
      FromValue(v, &field(*r));
    };
    return std::move(*this);
  }
};

template <typename F>
Binding Key(std::string key, double min, double max, std::string help, F field) {
  using T = std::decay_t<decltype(field(std::declval<ResolvedSettings&>()))>;
  Binding b;
  b.spec.key = std::move(key);
  b.spec.type = TypeOf<T>();
  b.spec.min = min;
  b.spec.max = max;
  b.spec.help = std::move(help);
  b.get = [field](const ResolvedSettings& r) { return ToValue(field(r)); };
  b.set = [field](const SettingValue& v, ResolvedSettings* r) { FromValue(v, &field(*r)); };
  return b;
}

template <typename F>
Binding Key(std::string key, std::string help, F field) {
  return Key(std::move(key), -kInf, kInf, std::move(help), field);
}

// ---- the declarations: every key exactly once ----

// One line per key: name, [min, max,] help, the field it fills.
// clang-format off
std::vector<Binding> MakeBindings() {
  std::vector<Binding> k;
  // Tracking, local mapping, loop closing.
  k.push_back(Key("Tracking.KeyFrameFarPoints", 0, kInf, "map points a keyframe creates from depth beyond ThDepth", [](auto& r) -> auto& { return r.run.slam.tracker.keyframe_far_points; }));
  k.push_back(Key("Tracking.SkipWithheldPoints", "local-map points projecting where keypoints were withheld (people, the ignore mask) are hidden, not missed: not searched, not counted as visible for map-point culling; off: counted as ORB-SLAM3 counts every point in view", [](auto& r) -> auto& { return r.run.slam.tracker.skip_withheld_points; }));
  k.push_back(Key("Tracking.KeyFramesForWithheld", "the close-point keyframe rule (fewer than 100 close points tracked) with its bound divided by the fraction of the image not withheld (at least 0.3): people hiding the near scene make keyframes come sooner (only while local mapping is idle); off: ORB-SLAM3's fixed bound", [](auto& r) -> auto& { return r.run.slam.tracker.keyframes_for_withheld; }));
  k.push_back(Key("Atlas.NewMapWhenLost", "when a frame can be neither tracked nor relocalised, start a new map from it at once (merged later when place recognition finds the overlap); off: stay lost until relocalisation", [](auto& r) -> auto& { return r.run.slam.tracker.new_map_when_lost; }));
  k.push_back(Key("LocalMapping.BundleAdjustment", "local bundle adjustment after each keyframe", [](auto& r) -> auto& { return r.run.slam.mapper.local_ba; }));
  k.push_back(Key("LocalMapping.MaxLocalKeyFrames", 1, kInf, "keyframes optimised by local BA (current + best covisibles)", [](auto& r) -> auto& { return r.run.slam.mapper.max_local_keyframes; }));
  k.push_back(Key("LocalMapping.DenseSchurMaxPoses", 0, kInf, "local BA windows with up to this many optimised keyframes are solved by detslam's own Levenberg-Marquardt on the dense Schur complement (optim/schur_bundle.h), larger ones by Ceres; 0: always Ceres (local BA before 2026-12-07)", [](auto& r) -> auto& { return r.run.slam.mapper.ba_dense_schur_max_poses; }));
  k.push_back(Key("LocalMapping.Triangulate", "triangulate keypoints without close depth with covisible keyframes", [](auto& r) -> auto& { return r.run.slam.mapper.triangulate; }));
  k.push_back(Key("LoopClosing.Enabled", "loop detection and correction", [](auto& r) -> auto& { return r.run.slam.loop.enabled; }));
  k.push_back(Key("LoopClosing.CandidateRadius", 0, kInf, "loop candidates: keyframe centres within this distance (m); 0: no position gate (needs a vocabulary)", [](auto& r) -> auto& { return r.run.slam.loop.candidate_radius_m; }));
  k.push_back(Key("LoopClosing.ConsistentDetections", 1, kInf, "loops found by appearance: keyframes that must agree (the verifying one, its covisibles, the next ones)", [](auto& r) -> auto& { return r.run.slam.loop.consistent_detections; }));
  k.push_back(Key("Place.Vocabulary", "bag-of-words vocabulary file for relocalisation and loop detection (empty: the shipped one; none: no place recognition) (--vocabulary)", [](auto& r) -> auto& { return r.run.slam.vocabulary; }));
  k.push_back(Key("LoopClosing.GlobalBAIterations", 0, kInf, "global bundle adjustment iterations after a loop (0: none)", [](auto& r) -> auto& { return r.run.slam.loop.global_ba_iterations; }));
  k.push_back(Key("LoopClosing.MergeWeldKeyFrames", 0, kInf, "a merge's welding window: keyframes on each side of the seam bundle-adjusted, then fixed in the pose graph (0: the pose graph alone)", [](auto& r) -> auto& { return r.run.slam.loop.merge_weld_keyframes; }));
  k.push_back(Key("LoopClosing.MergeWeldIterations", 1, kInf, "iterations of a merge's welding bundle adjustment", [](auto& r) -> auto& { return r.run.slam.loop.merge_weld_iterations; }));
  // Det-SLAM dynamic filter.
  k.push_back(Key("Dynamic.Classes", "class names treated as dynamic (comma-separated); the segmenter returns only these", [](auto& r) -> auto& { return r.run.slam.dynamic.filter.dynamic_classes; })
                  .Also([](auto& r) -> auto& { return r.segmenter.dnn.classes; })
                  .Also([](auto& r) -> auto& { return r.segmenter.maskrcnn.classes; }));
  k.push_back(Key("Dynamic.Alpha", 0, kInf, "depth-step widening factor alpha of the depth interval", [](auto& r) -> auto& { return r.run.slam.dynamic.filter.alpha; }));
  k.push_back(Key("Dynamic.DepthStep", "the paper's depth-ROI step (off: mask step only)", [](auto& r) -> auto& { return r.run.slam.dynamic.filter.depth_step; }));
  k.push_back(Key("Dynamic.MaskDilation", 0, kInf, "dilate dynamic masks by this many pixels", [](auto& r) -> auto& { return r.run.slam.dynamic.filter.mask_dilation_px; }));
  k.push_back(Key("Dynamic.MinScore", 0, 1, "ignore instances scored below this", [](auto& r) -> auto& { return r.run.slam.dynamic.filter.min_score; }));
  k.push_back(Key("Dynamic.DominantDepth", "depth step: the object's depth from its dominant depth mode (off: the paper's raw min/max over the mask pixels)", [](auto& r) -> auto& { return r.run.slam.dynamic.filter.dominant_mode; }));
  k.push_back(Key("Dynamic.PreMask", "drop dynamic corners before the ORB spatial distribution", [](auto& r) -> auto& { return r.run.slam.dynamic.premask; }));
  k.push_back(Key("Dynamic.MemoryFrames", 0, kInf, "carry lost dynamic instances forward this many frames", [](auto& r) -> auto& { return r.run.slam.dynamic.memory_frames; }));
  k.push_back(Key("Dynamic.DepthTrackFrames", 0, kInf, "follow lost dynamic instances in the depth image for this many frames (0 = off)", [](auto& r) -> auto& { return r.run.slam.dynamic.depth_track_frames; }));
  k.push_back(Key("Dynamic.GeometricCheck", "reject movers the segmenter missed by their residual against the tracked pose", [](auto& r) -> auto& { return r.run.slam.dynamic.geometric.enabled; }));
  k.push_back(Key("Dynamic.GeometricK", 0, kInf, "geometric check threshold in robust standard deviations above the median", [](auto& r) -> auto& { return r.run.slam.dynamic.geometric.threshold.k; }));
  k.push_back(Key("Dynamic.GeometricCoherence", 0, kInf, "geometric check: a flagged neighbour confirms a candidate mover only when their residual vectors (observed minus projected position) differ by at most this fraction of the longer one (a moving object shifts its keypoints alike, mismatches point every way); 0: off", [](auto& r) -> auto& { return r.run.slam.dynamic.geometric.coherence; }));
  k.push_back(Key("Dynamic.GeometricMinResidual", 0, kInf, "floor on the geometric check threshold (pixels)", [](auto& r) -> auto& { return r.run.slam.dynamic.geometric.threshold.min_threshold; }));
  k.push_back(Key("Dynamic.GeometricRegionFrames", 0, kInf, "carry each cluster of movers the geometric check found, as a box with a depth range, this many frames: keypoints inside it at its depth are labelled movers too (0 = off; camera-rate masks use Segmentation.CameraRateGeometricRegionFrames)", [](auto& r) -> auto& { return r.run.slam.dynamic.geometric.region_frames; }));
  k.push_back(Key("Dynamic.GeometricRegionMinKeypoints", 1, kInf, "keypoints a cluster of geometric movers needs to become a region", [](auto& r) -> auto& { return r.run.slam.dynamic.geometric.region_min_keypoints; }));
  k.push_back(Key("Dynamic.GeometricRegionDepthRatio", 0, 0.99, "a geometric mover region holds its keypoints' depths (10th to 90th percentile) widened by this fraction", [](auto& r) -> auto& { return r.run.slam.dynamic.geometric.region_depth_ratio; }));
  k.push_back(Key("Dynamic.GeometricRegionGrowth", 0, kInf, "pixels per frame a geometric mover region's box grows by", [](auto& r) -> auto& { return r.run.slam.dynamic.geometric.region_growth_px; }));
  // Segmentation.
  k.push_back(Key("Segmentation.EveryK", 1, kInf, "segment every K-th frame; masks follow the optical flow in between (--segment-every)", [](auto& r) -> auto& { return r.run.slam.dynamic.segment_every; }));
  k.push_back(Key("Segmentation.FlowScale", 1, 4, "the optical flow that carries masks to frames not segmented themselves (--segment-every, camera rate) runs on the images reduced by this factor: 1, 2 or 4 (2: as complete masks as 1 on the tuning seeds, 2.5x faster)", [](auto& r) -> auto& { return r.run.slam.dynamic.propagation.flow_scale; }));
  k.push_back(Key("Segmentation.CarryGrowth", 0, kInf, "masks carried to frames not segmented themselves (--segment-every, camera rate) grow by this many pixels per input frame since their segmentation (limbs and turning bodies that the shift by the median optical flow does not follow)", [](auto& r) -> auto& { return r.run.slam.dynamic.propagation.grow_px_per_frame; }));
  k.push_back(Key("Segmentation.KeyFrameMaxMaskAge", 0, kInf, "camera-rate mode (asynchronous segmentation): a frame whose masks were segmented more than this many input frames earlier makes no keyframe", [](auto& r) -> auto& { return r.run.slam.dynamic.keyframe_max_mask_age; }));
  k.push_back(Key("Segmentation.KeyFrameMaxWait", 0, kInf, "camera-rate mode (asynchronous segmentation): a keyframe waits for masks at most Segmentation.KeyFrameMaxMaskAge frames old for at most this many input frames after the first frame that asked for it, then it is made with the masks it has", [](auto& r) -> auto& { return r.run.slam.dynamic.keyframe_max_wait; }));
  k.push_back(Key("Segmentation.KeyFrameCleanOwnMasks", "camera-rate mode (asynchronous segmentation): when the detector's result for a frame that became a keyframe comes, the keyframe's keypoints are labelled by it, the points it made on dynamic objects erased and older points' views there dropped", [](auto& r) -> auto& { return r.run.slam.dynamic.keyframe_clean_own_masks; }));
  k.push_back(Key("Segmentation.KeyFrameDeferMinInliers", 0, kInf, "camera-rate mode (asynchronous segmentation): a keyframe waits for fresh masks only while the frame tracks at least this many map points; below, it is made at once with the masks it has", [](auto& r) -> auto& { return r.run.slam.dynamic.keyframe_defer_min_inliers; }));
  k.push_back(Key("Segmentation.Detector", "dnn: first detector, .onnx (YOLOX) or Darknet .cfg (relative: models folder)", [](auto& r) -> auto& { return r.segmenter.detector; }));
  k.push_back(Key("Segmentation.Weights", "dnn: Darknet weights (empty: beside the detector)", [](auto& r) -> auto& { return r.segmenter.weights; }));
  k.push_back(Key("Segmentation.Names", "dnn: class names file (empty: coco.names beside the detector)", [](auto& r) -> auto& { return r.segmenter.names; }));
  k.push_back(Key("Segmentation.PersonMask", "dnn: person mask model (none: box masks at the dominant depth)", [](auto& r) -> auto& { return r.segmenter.person_mask; }));
  k.push_back(Key("Segmentation.ScoreThreshold", 0, 1, "minimum detection score (dnn; maskrcnn uses 0.5 unless set)", [](auto& r) -> auto& { return r.segmenter.dnn.score_threshold; })
                  .Also([](auto& r) -> auto& { return r.segmenter.maskrcnn.score_threshold; }));
  k.push_back(Key("Segmentation.NmsThreshold", 0, 1, "dnn: IoU above which same-class boxes are suppressed", [](auto& r) -> auto& { return r.segmenter.dnn.nms_threshold; }));
  k.push_back(Key("Segmentation.BoxExpand", 0, kInf, "dnn: person box grown by this fraction per side for the mask crop", [](auto& r) -> auto& { return r.segmenter.dnn.box_expand; }));
  k.push_back(Key("Segmentation.InputSize", 32, kInf, "dnn: YOLOX input side (multiple of 32)", [](auto& r) -> auto& { return r.segmenter.dnn.yolox_input_size; }));
  k.push_back(Key("Segmentation.CameraRateOpenCvThreads", 0, kInf, "camera-rate mode (--realtime): OpenCV threads during the run (the detector's network is their main user; process-wide), 0 = OpenCV's default (one per core)", [](auto& r) -> auto& { return r.run.camera_rate_opencv_threads; }));
  k.push_back(Key("Segmentation.CameraRateFirstFrameWaits", "camera-rate mode (asynchronous segmentation): the first frame waits for its own masks and is tracked, and the frames that arrived before them are dropped (not queued behind it); off: the first frame is only segmented and tracking starts with the next frame, its masks carried from the first", [](auto& r) -> auto& { return r.run.first_frame_waits_for_masks; }));
  k.push_back(Key("Segmentation.CameraRateNice", 0, 19, "camera-rate mode: nice value of the asynchronous segmentation thread (Linux; the frames' path runs at 0), and of the local-mapping and loop-closing threads where Segmentation.CameraRateMappingNice is -1", [](auto& r) -> auto& { return r.run.background_nice; }));
  k.push_back(Key("Segmentation.CameraRateIdleSegmentation", "camera-rate mode (Linux): the asynchronous segmentation thread under the SCHED_IDLE policy (it gets a core only when no other thread wants it, and a frame's thread takes its core at once) instead of nice Segmentation.CameraRateNice", [](auto& r) -> auto& { return r.run.idle_segmentation; }));
  k.push_back(Key("Segmentation.CameraRateMaxBusy", 0, 1, "camera-rate mode (Linux): before each frame it takes, the asynchronous segmentation thread waits while the machine's cores were busy more than this share of the last 100 ms (all processes; 1 = never waits), at most Segmentation.CameraRateHeadroomMaxWait ms: a virtual machine whose cores are all kept busy may have a core stopped by its host for a whole period (about 100 ms), and a frame on it waits that long", [](auto& r) -> auto& { return r.run.camera_rate_max_busy; }));
  k.push_back(Key("Segmentation.CameraRateHeadroomMaxWait", 0, kInf, "camera-rate mode: the longest wait (ms) of the segmentation thread for idle cores before each frame it takes (Segmentation.CameraRateMaxBusy)", [](auto& r) -> auto& { return r.run.camera_rate_headroom_max_wait_ms; }));
  k.push_back(Key("Segmentation.CameraRateMappingNice", -1, 19, "camera-rate mode: nice value of the local-mapping and loop-closing threads (-1: Segmentation.CameraRateNice)", [](auto& r) -> auto& { return r.run.mapping_nice; }));
  k.push_back(Key("Segmentation.CameraRateParallelExtraction", "camera-rate mode (asynchronous segmentation): the part of a frame's feature extraction that needs no masks (pyramid, strong FAST corners) runs in a helper thread while the frame's masks are carried to it (the keypoints are the same either way)", [](auto& r) -> auto& { return r.run.parallel_extraction; }));
  k.push_back(Key("Segmentation.CameraRateGeometricRegionFrames", 0, kInf, "asynchronous segmentation (--realtime, --simulate-camera-rate-masks): Dynamic.GeometricRegionFrames used there (a person entering the view is in the masks only frames later)", [](auto& r) -> auto& { return r.run.camera_rate_region_frames; }));
  k.push_back(Key("Segmentation.CameraRateInputSize", 32, kInf, "dnn, camera-rate mode (--realtime): YOLOX input side (multiple of 32) used there instead of Segmentation.InputSize (a faster detector gives fresher masks)", [](auto& r) -> auto& { return r.segmenter.camera_rate_input_size; }));
  k.push_back(Key("Segmentation.PersonMaskMinFill", 0, 1, "dnn: person mask fill of the box below which the depth mask is used", [](auto& r) -> auto& { return r.segmenter.dnn.person_mask_min_fill; }));
  k.push_back(Key("Segmentation.SecondDetector", "dnn: second detector for boxes the first missed (empty: yolo-fastest-1.1-xl when found; none)", [](auto& r) -> auto& { return r.segmenter.second_detector; }));
  k.push_back(Key("Segmentation.SecondWeights", "dnn: Darknet weights of the second detector (empty: beside it)", [](auto& r) -> auto& { return r.segmenter.second_weights; }));
  k.push_back(Key("Segmentation.SecondNames", "dnn: class names of the second detector (empty: beside it)", [](auto& r) -> auto& { return r.segmenter.second_names; }));
  k.push_back(Key("Segmentation.SecondScoreThreshold", 0, 1, "dnn: minimum score of the second detector", [](auto& r) -> auto& { return r.segmenter.dnn.second_score_threshold; }));
  k.push_back(Key("Segmentation.SecondEvery", 1, kInf, "dnn: run the second detector on every N-th segmented frame", [](auto& r) -> auto& { return r.segmenter.dnn.second_every; }));
  k.push_back(Key("Segmentation.MaskRcnnGraph", "maskrcnn: frozen graph (.pb)", [](auto& r) -> auto& { return r.segmenter.maskrcnn_graph; }));
  k.push_back(Key("Segmentation.MaskRcnnConfig", "maskrcnn: OpenCV graph config (.pbtxt)", [](auto& r) -> auto& { return r.segmenter.maskrcnn_config; }));
  k.push_back(Key("Segmentation.MaskRcnnNames", "maskrcnn: class names file", [](auto& r) -> auto& { return r.segmenter.maskrcnn_names; }));
  // Camera (read with the camera keys; settable with --set).
  k.push_back(Key("RGBD.DisparitySigma", 0, kInf, "disparity noise (px) weighting the depth residual; 0: ORB-SLAM3's octave sigma", [](auto& r) -> auto& { return r.camera.disparity_sigma; }));
  return k;
}
// clang-format on

const std::vector<Binding>& Bindings() {
  static const std::vector<Binding> bindings = [] {
    std::vector<Binding> b = MakeBindings();
    const ResolvedSettings defaults;
    for (Binding& x : b) x.spec.default_value = x.get(defaults);
    return b;
  }();
  return bindings;
}

// Keys that were renamed: old -> new.
const std::map<std::string, std::string>& RenamedKeys() {
  static const std::map<std::string, std::string> renamed = {
      {"Segmentation.DynamicClasses", "Dynamic.Classes"}};
  return renamed;
}

bool InOwnNamespace(const std::string& key) {
  for (const char* prefix :
       {"Tracking.", "LocalMapping.", "LoopClosing.", "Place.", "Dynamic.", "Segmentation."}) {
    if (key.rfind(prefix, 0) == 0) return true;
  }
  return false;
}

}  // namespace

const std::vector<SettingSpec>& DeclaredSettings() {
  static const std::vector<SettingSpec> specs = [] {
    std::vector<SettingSpec> s;
    for (const Binding& b : Bindings()) s.push_back(b.spec);
    return s;
  }();
  return specs;
}

ResolvedSettings ResolveSettings(const Settings& settings) {
  ResolvedSettings r;
  r.camera = settings.camera;
  std::string ignored;
  for (const auto& [key, text] : settings.extra) {
    const auto origin = settings.extra_origin.find(key);
    const std::string where =
        origin != settings.extra_origin.end() ? origin->second : settings.source;
    const Binding* binding = nullptr;
    for (const Binding& b : Bindings()) {
      if (b.spec.key == key) binding = &b;
    }
    if (binding != nullptr) {
      SettingValue value;
      std::string why;
      if (!ParseSettingValue(binding->spec, text, &value, &why))
        throw InputError(where, 0, "key '" + key + "' " + why);
      binding->set(value, &r);
      continue;
    }
    const auto renamed = RenamedKeys().find(key);
    if (renamed != RenamedKeys().end()) {
      throw InputError(where, 0, "key '" + key + "' was renamed to '" + renamed->second + "'");
    }
    if (where.rfind("--set ", 0) == 0 || InOwnNamespace(key)) {
      throw InputError(where, 0,
                       "unknown key '" + key + "'; did you mean '" +
                           ClosestSettingKey(key, DeclaredSettings()) +
                           "'? (detslam settings --list)");
    }
    ignored += (ignored.empty() ? "" : ", ") + key;
  }
  if (!ignored.empty())
    spdlog::debug("{}: keys detslam does not use, ignored: {}", settings.source, ignored);
  return r;
}

std::vector<std::pair<std::string, SettingValue>> SettingValues(const ResolvedSettings& resolved) {
  std::vector<std::pair<std::string, SettingValue>> values;
  for (const Binding& b : Bindings()) values.emplace_back(b.spec.key, b.get(resolved));
  return values;
}

nlohmann::json EffectiveSettingsJson(const Settings& settings, const RunOptions& options) {
  ResolvedSettings r = ResolveSettings(settings);
  r.run = options;
  nlohmann::json j = nlohmann::json::object();
  for (const auto& [key, value] : SettingValues(r)) {
    std::visit([&j, k = key](const auto& v) { j[k] = v; }, value);
  }
  return j;
}

}  // namespace detslam
