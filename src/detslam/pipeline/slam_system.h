// The RGB-D SLAM stages wired together for one sequence: feature extraction, tracking, local
// mapping, and the trajectory bookkeeping that places every tracked frame relative to its
// reference keyframe (so later map corrections move the frames with their keyframes).
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <thread>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "detslam/dynamic/dynamic_filter.h"
#include "detslam/features/orb_extractor.h"
#include "detslam/io/trajectory.h"
#include "detslam/loop/loop_closer.h"
#include "detslam/map/map.h"
#include "detslam/mapping/local_mapper.h"
#include "detslam/pipeline/bounded_queue.h"
#include "detslam/tracking/tracker.h"

namespace detslam {

struct SlamOptions {
  OrbOptions orb;
  TrackerOptions tracker;
  LocalMapperOptions mapper;
  LoopClosingOptions loop;        // loop closing after local mapping of each keyframe
  DynamicFilterOptions dynamic;   // Det-SLAM filter (used when instances are passed in)
  bool dynamic_premask = true;    // also drop dynamic corners before the ORB spatial distribution
  bool mapping_thread = false;    // local mapping in its own thread (not deterministic)
  int dynamic_memory_frames = 3;  // carry lost dynamic instances forward this many frames (0.1 s)
  bool Check(std::string* error) const;
};

// Wall-clock time of each stage for one frame, milliseconds.
struct FrameTimings {
  double extraction_ms = 0, tracking_ms = 0, mapping_ms = 0;
};

struct FrameReport {
  int64_t index = 0;
  int dynamic_instances = 0;  // dynamic instances the filter used
  int rejected_keypoints = 0; // keypoints rejected by the dynamic filter (after extraction)
  double segmentation_ms = 0; // time of the segmenter for this frame
  Timestamp stamp;
  TrackingResult tracking;
  bool keyframe = false;
  bool loop_closed = false;   // this frame's keyframe closed a loop (sequential/inline mapping)
  int num_keypoints = 0;
  FrameTimings timings;
};

class SlamSystem {
 public:
  SlamSystem(const PinholeCamera& camera, const SlamOptions& options);
  ~SlamSystem();
  SlamSystem(const SlamSystem&) = delete;
  SlamSystem& operator=(const SlamSystem&) = delete;

  // Waits until the mapping thread (if any) has processed every queued keyframe and stops it.
  // Call before reading the trajectory or the map; ProcessFrame/TrackFrame must not follow.
  void Finish();

  // Processes one RGB-D frame: ExtractFrame then TrackFrame. gray: CV_8UC1; depth_m: CV_32FC1
  // metres (0 = missing); ignore_mask: empty or CV_8UC1, non-zero = no keypoints there.
  FrameReport ProcessFrame(int64_t index, Timestamp stamp, const cv::Mat& gray,
                           const cv::Mat& depth_m, const cv::Mat& ignore_mask = cv::Mat());

  // Feature extraction stage: thread-safe (const), may run ahead of tracking in another thread.
  // With `instances` (from a segmenter), the Det-SLAM filter rejects keypoints on dynamic objects:
  // they are moved to the frame's rejected list (labelled) and never reach tracking. Fills
  // report->timings.extraction_ms, num_keypoints and the dynamic counters.
  Frame ExtractFrame(int64_t index, Timestamp stamp, const cv::Mat& gray, const cv::Mat& depth_m,
                     const cv::Mat& ignore_mask, FrameReport* report,
                     const std::vector<Instance>* instances = nullptr) const;
  // Tracking and (for keyframes) local mapping of an extracted frame, in input order.
  void TrackFrame(Frame frame, FrameReport* report);

  // Every tracked frame's pose, recomputed from its reference keyframe's current pose.
  Trajectory FrameTrajectory() const;
  // Keyframe poses (world_from_cam) in id order.
  Trajectory KeyFrameTrajectory() const;
  const Map& map() const { return map_; }
  // Local-mapping time of every processed keyframe (ms), in processing order.
  const std::vector<double>& mapping_times_ms() const { return mapping_times_ms_; }
  // Loops closed so far.
  int loops_closed() const { return loop_closer_.loops_closed(); }

 private:
  Rigid3d ReferenceWorldFromCam(KeyFrameId id, const Rigid3d& cam_from_ref) const;
  void MapKeyFrame(KeyFrameId kf, FrameReport* report);
  void MappingLoop();

  PinholeCamera camera_;
  SlamOptions options_;
  OrbExtractor extractor_;
  Map map_;
  Tracker tracker_;
  LocalMapper mapper_;
  struct TrackedFrame {
    Timestamp stamp;
    KeyFrameId reference;
    Rigid3d cam_from_ref;
  };
  std::vector<TrackedFrame> tracked_;
  std::map<KeyFrameId, ErasedKeyFrame> erased_;
  std::vector<double> mapping_times_ms_;
  LoopCloser loop_closer_;
  // Mapping thread: the map store's one lock guards map_, tracker_ state and erased_ while both
  // threads run; the queue hands keyframes from tracking to mapping.
  std::mutex map_mutex_;
  std::unique_ptr<BoundedQueue<KeyFrameId>> keyframe_queue_;
  std::thread mapping_thread_;
};

ScaleInfo MakeScaleInfo(const OrbExtractor& extractor);

}  // namespace detslam
