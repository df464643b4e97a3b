// The RGB-D SLAM stages wired together for one sequence: feature extraction, tracking, local
// mapping, and the trajectory bookkeeping that places every tracked frame relative to its
// reference keyframe (so later map corrections move the frames with their keyframes).
#pragma once

#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <opencv2/core.hpp>
#include <string>
#include <thread>
#include <vector>

#include "detslam/dynamic/detslam_stage.h"
#include "detslam/features/orb_extractor.h"
#include "detslam/io/trajectory.h"
#include "detslam/loop/loop_closer.h"
#include "detslam/map/map.h"
#include "detslam/map/map_file.h"
#include "detslam/map/map_store.h"
#include "detslam/mapping/local_mapper.h"
#include "detslam/place/vocabulary.h"
#include "detslam/tracking/tracker.h"

namespace detslam {

struct SlamOptions {
  OrbOptions orb;
  TrackerOptions tracker;
  LocalMapperOptions mapper;
  LoopClosingOptions loop;  // loop closing after local mapping of each keyframe
  DetSlamOptions dynamic;   // the Det-SLAM stage (segmentation, filter, geometric check)
  // Bag-of-words vocabulary for relocalisation and loop detection: a file, "" for the shipped one
  // (DefaultVocabularyPath), or "none": no place recognition (relocalisation tries every keyframe
  // by brute force, loops are found by position only).
  std::string vocabulary;
  // The global bundle adjustment after a loop: false (default) runs it in the mapping stage right
  // after the loop (deterministic); true runs it in a thread of its own, so that neither tracking
  // nor local mapping waits for it (the threaded runner with a mapping thread sets this). A new
  // loop waits for the previous one's to finish.
  bool global_ba_thread = false;
  // Loop closing in a thread of its own (ORB-SLAM3's LoopClosing thread): the caller runs
  // MapKeyFrame in the local-mapping thread and CloseLoops, for each keyframe it finished, in
  // a loop-closing thread, so local mapping never waits for the loop search and verification. A
  // correction (fusion, pose graph, a merge's weld) waits for local mapping to finish the keyframe
  // it is mapping and holds local mapping while it runs (ORB-SLAM3 stops local mapping for it);
  // tracking goes on between its steps. false: MapKeyFrame closes loops right after local mapping.
  bool loop_thread = false;
  // Localisation mode (with a loaded map, LoadMap): track against the map only; no keyframes, no
  // map points, no local mapping or loop closing. Between relocalisations the tracker follows the
  // camera on frame-to-frame points from depth (visual odometry).
  bool localization = false;
  bool Check(std::string* error) const;
};

// One loop closed (run.json `loops`).
struct LoopRecord {
  int64_t frame = -1;                  // input frame of the keyframe that closed it
  KeyFrameId keyframe = kNoKeyFrame;   // that keyframe
  KeyFrameId candidate = kNoKeyFrame;  // the older keyframe of the same place
  int64_t candidate_frame = -1;        // and the input frame it was made from
  int inliers = 0;                     // verified inliers
  int agreeing = 0;                    // keyframes that agreed on it
  double correction_m = 0;             // how far the pose graph moved the keyframe
  // The keyframe's verified pose in the candidate's camera frame, as the loop asserts it
  // (LoopClosingResult::candidate_from_keyframe).
  Rigid3d candidate_from_keyframe;
  bool merge = false;                  // the candidate was in another map: two maps merged
  int merged_from = -1, merged_into = -1;
  int welded_keyframes = 0;  // a merge: keyframes its seam's bundle adjustment optimised
  // Loop closing in its own thread (SlamOptions::loop_thread): how long the correction waited for
  // local mapping to finish its keyframe, and how long it then held local mapping; 0 otherwise.
  double mapping_wait_ms = 0, mapping_held_ms = 0;
  // When the correction was applied: the newest input frame tracked by then (a mapping thread
  // corrects some frames after the keyframe's), and the longest time loop closing held the map's
  // lock in one step for this keyframe (candidate search, one candidate's verification, or the
  // correction with fusion and pose graph): the longest tracking could have waited for it.
  int64_t corrected_after_frame = -1;
  double map_locked_ms = 0;
};

// Every tracked frame's pose, by the map of the atlas that holds it at the end of the run (maps
// merged into another count as that one).
struct MapTrajectories {
  int main_map = -1;  // the map of the first frame with a pose
  std::map<int, Trajectory> by_map;
};

// Wall-clock time of each stage for one frame, milliseconds.
struct FrameTimings {
  double extraction_ms = 0, tracking_ms = 0, mapping_ms = 0;
  // Of tracking_ms: the wait for the map's lock (held by local mapping or loop closing when they
  // run in another thread).
  double map_wait_ms = 0;
  // The CPU time the tracking thread used for tracking_ms (its cost without waits and without
  // time the other threads took the core from it; -1 where the platform cannot tell).
  double tracking_cpu_ms = -1;
};

struct FrameReport {
  int64_t index = 0;
  int dynamic_instances = 0;   // dynamic instances the filter used
  int rejected_keypoints = 0;  // keypoints rejected by the dynamic filter (after extraction)
  double segmentation_ms = 0;  // time of the segmenter for this frame (asynchronous: of carrying
                               // the newest masks to it)
  // Asynchronous segmentation: the input frame whose segmentation this frame's masks come from,
  // and their age in input frames (0: its own); -1 when not asynchronous or no masks yet.
  int64_t mask_source = -1;
  int mask_age = -1;
  // The tracker asked for a keyframe but the frame's masks were older than
  // DetSlamOptions::keyframe_max_mask_age: no keyframe was made from it.
  bool keyframe_deferred = false;
  // A keyframe was made from masks older than that limit: tracking had become too weak to wait
  // (DetSlamOptions::keyframe_defer_min_inliers), it had waited keyframe_max_wait frames, or the
  // keyframe is a new map's first (a map starts whatever its masks' age).
  bool keyframe_stale_masks = false;
  // DetSlamOptions::keyframe_clean_own_masks: the keypoints of an earlier keyframe relabelled by
  // its own masks, published before this frame (-1: none this frame).
  int keyframe_cleaned = -1;
  Timestamp stamp;
  TrackingResult tracking;
  bool keyframe = false;
  int map_id = -1;  // the map of the atlas the frame was tracked in (-1: no pose)
  // With tracking.pose_valid: the frame's pose as tracked, in map map_id's frame (later loop
  // corrections and merges move it; FrameTrajectories has the final poses).
  Rigid3d world_from_cam;
  bool loop_closed = false;  // this frame's keyframe closed a loop (mapping in the tracking thread)
  KeyFrameId loop_keyframe = kNoKeyFrame;   // with loop_closed: the keyframe that closed it
  KeyFrameId loop_candidate = kNoKeyFrame;  //   the older keyframe of the same place
  int64_t loop_candidate_frame = -1;        //   and the input frame it was made from
  int loop_inliers = 0;                     //   verified inliers
  int loop_agreeing = 0;                    //   keyframes that agreed on it
  double loop_correction_m = 0;             //   how far the pose graph moved the keyframe
  bool maps_merged = false;                 //   it was a merge of two maps
  int num_keypoints = 0;
  // Size of the atlas (every map) right after tracking this frame; in threaded mode the mapping
  // thread may still add to it.
  int map_keyframes = 0;
  int map_points = 0;
  FrameTimings timings;
  // Camera-rate mode (RunOptions::realtime): milliseconds from the frame's arrival to its pose
  // (the end of tracking); -1 otherwise.
  double latency_ms = -1;
  // Why the frame was skipped (its images could not be read: corrupt, wrong type or size, gone);
  // empty for a processed frame. A skipped frame has no pose and is not seen by tracking.
  std::string skipped;
};

// The SLAM stages of one sequence. It starts no thread: the runner calls ExtractFrame,
// TrackFrame and MapKeyFrame from whichever threads it runs them in (pipeline/runner.cc).
// ExtractFrame is const and may run ahead; TrackFrame must see the frames in input order and
// MapKeyFrame the keyframes in the order TrackFrame made them. TrackFrame and MapKeyFrame may run
// concurrently: the map store's lock guards the map, the tracker's state and the trajectory
// bookkeeping.
class SlamSystem {
 public:
  // `segmenter` (may be null: no dynamic-object filtering) feeds the Det-SLAM stage. Throws
  // InputError when the vocabulary cannot be loaded.
  SlamSystem(const PinholeCamera& camera, const SlamOptions& options,
             Segmenter* segmenter = nullptr);
  SlamSystem(const SlamSystem&) = delete;
  SlamSystem& operator=(const SlamSystem&) = delete;
  ~SlamSystem();

  // Processes one RGB-D frame in the calling thread: ExtractFrame, TrackFrame and, for a new
  // keyframe, MapKeyFrame. gray: CV_8UC1; depth_m: CV_32FC1 metres (0 = missing); ignore_mask:
  // empty or CV_8UC1, non-zero = no keypoints there.
  FrameReport ProcessFrame(int64_t index, Timestamp stamp, const cv::Mat& gray,
                           const cv::Mat& depth_m, const cv::Mat& ignore_mask = cv::Mat());

  // Loading stage (frames in input order): the frame's dynamic instances from the Det-SLAM stage
  // (segmenter, instance memory, mask propagation). Not segmented without a segmenter.
  FrameInstances SegmentFrame(const SegmenterInput& input, const cv::Mat& gray);
  // Asynchronous segmentation's thread: the segmenter (and instance memory) on one frame, without
  // mask propagation (DetSlamStage::Detect).
  FrameInstances DetectFrame(const SegmenterInput& input);
  // Feature extraction stage: thread-safe (const), may run ahead of tracking in another thread.
  // With `instances` (from SegmentFrame), the Det-SLAM stage labels keypoints on dynamic objects:
  // they are moved to the frame's rejected list (labelled) and never reach tracking. Fills
  // report->timings.extraction_ms, num_keypoints and the dynamic counters. `pyramid`: null, or
  // PrepareExtraction(gray) computed earlier (e.g. in another thread while the frame's masks were
  // carried to it; its time is not in extraction_ms then); the result is the same.
  Frame ExtractFrame(int64_t index, Timestamp stamp, const cv::Mat& gray, const cv::Mat& depth_m,
                     const cv::Mat& ignore_mask, FrameReport* report,
                     const std::vector<Instance>* instances = nullptr,
                     const OrbPyramid* pyramid = nullptr) const;
  // The part of ExtractFrame that needs no masks (OrbExtractor::Prepare); thread-safe (const).
  OrbPyramid PrepareExtraction(const cv::Mat& gray) const { return extractor_.Prepare(gray); }
  // Tracking stage: tracks an extracted frame (input order) and makes it a keyframe when the
  // tracker asks for one. Returns the new keyframe for MapKeyFrame, or kNoKeyFrame. With
  // `tracked`, the frame as tracked (its keypoints' landmarks, outliers and labels) is moved there
  // (for a viewer).
  KeyFrameId TrackFrame(Frame frame, FrameReport* report, Frame* tracked = nullptr);
  // Asynchronous segmentation with DetSlamOptions::keyframe_clean_own_masks: the detector's result
  // for input frame `index` (its dynamic instances and the frame's depth, CV_32FC1 metres). If
  // that frame became a keyframe (with carried masks), the next TrackFrame cleans the keyframe
  // with them. Thread-safe (the segmentation thread calls it); a newer result replaces one not
  // used yet.
  void OfferOwnMasks(int64_t index, const std::vector<Instance>& instances, const cv::Mat& depth_m);
  // Local mapping stage: local mapping of a keyframe from TrackFrame and, unless loop closing has
  // a thread of its own (SlamOptions::loop_thread), its loop closing. Fills
  // report->timings.mapping_ms and the loop fields.
  void MapKeyFrame(KeyFrameId kf, FrameReport* report);
  // Loop-closing stage (SlamOptions::loop_thread): loop detection and closing of a keyframe that
  // MapKeyFrame finished, in the order MapKeyFrame finished them. Fills the report's loop fields.
  void CloseLoops(KeyFrameId kf, FrameReport* report);

  // Every tracked frame's pose, recomputed from its reference keyframe's current pose, by map.
  MapTrajectories FrameTrajectories() const;
  // Those of the main map (the map of the first tracked frame, with every map merged into it).
  Trajectory FrameTrajectory() const;
  // Keyframe poses (world_from_cam) of the main map in id order.
  Trajectory KeyFrameTrajectory() const;
  // Read access to the map (holds the lock while it lives).
  MapStore::ReadAccess ReadMap() const { return store_.Read(); }
  // Local-mapping time of every processed keyframe (ms), in processing order (with the loop
  // closing of the keyframe unless it has a thread of its own).
  std::vector<double> mapping_times_ms() const;
  // Loop-closing time of every keyframe it processed (ms): the search, verification and any
  // correction, not the global BA that follows.
  std::vector<double> loop_closing_times_ms() const;
  // Loops closed so far (merges not included), maps merged so far.
  int loops_closed() const;
  int maps_merged() const;
  std::vector<LoopRecord> loops() const;
  // Waits for a global bundle adjustment running in its own thread (global_ba_thread), e.g.
  // before the trajectory is written. The destructor stops it instead (after its current
  // iteration, progress kept).
  void WaitForGlobalBundleAdjustment();
  // Thread-safe: a running global BA stops after its current iteration (progress kept) and no new
  // one starts; for a run that is being stopped (e.g. Ctrl-C).
  void Interrupt();
  // Global bundle adjustments started, and those stopped early because a newer loop was closed
  // while they ran (their solution is discarded: it predates that loop's correction).
  int global_ba_runs() const;
  int global_ba_stopped() const;
  // Threaded runs: keyframes local mapping processed without fusion, BA or keyframe culling
  // because more keyframes were waiting (a burst); 0 in sequential runs.
  int keyframes_mapped_in_burst() const { return keyframes_mapped_in_burst_; }
  // For each global BA whose solution was applied to the map: the newest input frame tracked by
  // then.
  std::vector<int64_t> global_ba_applied_after_frames() const;
  LoopDetectionStats loop_detection_stats() const;
  // Starts from the map in a map file (before the first frame): the tracker relocalises in it
  // from the first frame on; new keyframes extend it unless in localisation mode. Throws
  // InputError naming the file when it is damaged or was made with another camera, ORB pyramid
  // or vocabulary.
  MapFileInfo LoadMap(const std::string& path);
  // Writes the map to a map file (map/map_file.h) with this run's camera, pyramid and vocabulary
  // checksum, atomically; returns the file's size in bytes. Throws InputError on failure.
  uint64_t SaveMap(const std::string& path) const;
  // Whether loop closing runs in a thread of its own (SlamOptions::loop_thread).
  bool loop_thread() const { return options_.loop_thread; }
  // The vocabulary file in use ("none" without place recognition).
  const std::string& vocabulary_path() const { return vocabulary_path_; }

 private:
  // The pose of a tracked frame from its reference keyframe (walking up through erased ones), and
  // the keyframe it ended at.
  Rigid3d ReferenceWorldFromCam(const Map& map, KeyFrameId id, const Rigid3d& cam_from_ref,
                                KeyFrameId* existing = nullptr) const;

  // DetSlamOptions::keyframe_clean_own_masks: relabels the keyframe made from the frame of the
  // newest offered masks (OfferOwnMasks), if any, by them and drops its landmarks there; returns
  // the keypoints relabelled (-1: no such keyframe, or no masks offered since the last call).
  int CleanKeyFrameWithOwnMasks(Map& map);

  PinholeCamera camera_;
  SlamOptions options_;
  OrbExtractor extractor_;
  std::string vocabulary_path_;
  std::shared_ptr<const Vocabulary> vocabulary_;  // null with vocabulary "none"
  DetSlamStage dynamic_;
  MapStore store_;  // the map's one owner; its lock also guards everything below
  Tracker tracker_;
  LocalMapper mapper_;
  LoopCloser loop_closer_;
  struct TrackedFrame {
    Timestamp stamp;
    KeyFrameId reference;
    Rigid3d cam_from_ref;
  };
  std::vector<TrackedFrame> tracked_;
  std::map<KeyFrameId, ErasedKeyFrame> erased_;
  std::vector<double> mapping_times_ms_;
  std::vector<double> loop_closing_times_ms_;
  // With loop_thread: held by local mapping while it maps a keyframe and by loop closing while it
  // corrects the map, so the two never interleave their steps (the correction needs the map as
  // local mapping left it, and a local BA solved meanwhile would undo the correction).
  std::mutex mapping_turn_;
  std::vector<LoopRecord> loops_;
  int64_t last_tracked_frame_ = -1;  // the newest frame TrackFrame has seen
  int64_t keyframe_wait_since_ = -1;  // the first frame whose keyframe was deferred (-1: none)
  // DetSlamOptions::keyframe_clean_own_masks: the newest masks offered, not used yet.
  struct OwnMasks {
    int64_t index = -1;
    DynamicRegions regions;
  };
  std::mutex offered_mutex_;
  std::optional<OwnMasks> offered_;  // guarded by offered_mutex_
  std::vector<int64_t> global_ba_applied_;  // global_ba_applied_after_frames()
  std::thread global_ba_;  // with global_ba_thread: the running (or last) global BA
  int loop_generation_ = 0;  // loops corrected so far (a global BA started before one is stale)
  std::atomic<bool> stop_global_ba_{false};     // asks the running global BA to stop
  std::atomic<bool> global_ba_running_{false};  // a global BA thread has not finished yet
  std::atomic<bool> interrupted_{false};        // Interrupt(): no new global BA
  std::atomic<int> global_ba_runs_{0};
  std::atomic<int> global_ba_stopped_{0};
  // Keyframes TrackFrame made that MapKeyFrame has not finished (0 before every frame of a
  // sequential run), and the tracker's request to cut the running local BA short.
  std::atomic<int> keyframes_to_map_{0};
  std::atomic<bool> abort_local_ba_{false};
  std::atomic<int> keyframes_mapped_in_burst_{0};  // mapped without fusion / BA (keyframes waited)
};

ScaleInfo MakeScaleInfo(const OrbExtractor& extractor);

}  // namespace detslam
