// What the viewer's web page shows, as immutable snapshots: a frame (image, dynamic masks,
// keypoints by what became of them, tracking state), the map (points, keyframes, trajectory,
// aligned ground truth) and the run's counters. Two sources make them: a live run
// (live_viewer.h) and a finished run's folder (run_view.h); the server (viewer_server.h) turns
// them into HTTP answers.
#pragma once

#include <Eigen/Core>
#include <array>
#include <chrono>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "detslam/core/rigid3d.h"
#include "detslam/io/trajectory.h"

namespace detslam {

// What became of a keypoint (the colours of the page's legend).
enum class KeypointFate : int {
  kMatched = 0,    // kept, and matched to a map point (a pose inlier)
  kUnmatched = 1,  // kept, no map point (or an outlier)
  kMask = 2,       // rejected: on a dynamic object's mask
  kDepth = 3,      // rejected: the depth step inside a detection box
  kGeometric = 4,  // withheld: the geometric check found it moving
};
constexpr int kNumKeypointFates = 5;
const char* KeypointFateName(KeypointFate fate);

struct ViewerFrame {
  uint64_t seq = 0;    // snapshot number (increases)
  int64_t index = -1;  // input frame
  double stamp_s = 0;
  std::string state, method;  // tracking state ("OK", "LOST", ...) and how it was tracked
  bool tracked = false, keyframe = false;
  std::string skipped;  // why its images could not be read (empty: read)
  int inliers = 0, dynamic_instances = 0;
  double frame_ms = 0;  // segmentation + extraction + tracking + mapping
  int map_id = -1;
  std::optional<Rigid3d> world_from_cam;
  cv::Mat bgr;  // colour image (may be empty)
  // Pixels drawn over the image as dynamic: instance masks (live) or the keyframe's removed
  // pixels (a finished run's keyframe_masks/); each CV_8UC1, image size, non-zero = dynamic.
  std::vector<cv::Mat> masks;
  std::vector<cv::Rect> boxes;  // detection boxes
  bool has_keypoints = false;   // a finished run keeps no keypoints
  // Keypoint positions (x0, y0, x1, y1, ... pixels) by KeypointFate.
  std::array<std::vector<float>, kNumKeypointFates> keypoints;
};

struct ViewerMap {
  uint64_t seq = 0;
  int map_id = -1;                     // the map of the atlas shown (where the camera is)
  std::vector<float> points;           // x, y, z of each map point
  std::vector<Rigid3d> keyframes;      // world_from_cam
  std::vector<Eigen::Vector3d> trajectory;    // every tracked frame, final poses
  std::vector<Eigen::Vector3d> ground_truth;  // rigidly aligned to the trajectory (may be empty)
};

struct ViewerCounters {
  std::string mode;  // "live" or "run" (a finished run's folder)
  std::string state;  // tracking state after the newest frame ("" before the first)
  int64_t frame = -1, frames_done = 0, total = 0, tracked = 0;
  int64_t keyframes = 0, points = 0, loops = 0, merges = 0, maps = 0, relocalizations = 0;
  double fps = 0;
  bool pausable = false, paused = false, finished = false;
  int pages = 0;  // pages connected to the update stream
  // Update number these counters were read at: a page keeps the newest of the stream's and a
  // control request's replies, which can arrive in either order.
  uint64_t seq = 0;
};

class ViewerContent {
 public:
  virtual ~ViewerContent() = default;
  // A run description for the page's title: dataset, segmenter, mode.
  virtual std::string Title() const = 0;
  // Blocks until the update number passes `seen` or `timeout` passes; returns it.
  virtual uint64_t WaitForUpdate(uint64_t seen, std::chrono::milliseconds timeout) = 0;
  virtual ViewerCounters Counters() const = 0;
  // Frame `index` (-1: the newest); null when it is not available.
  virtual std::shared_ptr<const ViewerFrame> Frame(int64_t index) = 0;
  // The newest map snapshot; asks for a fresh one (null until the first).
  virtual std::shared_ptr<const ViewerMap> Map() = 0;
  // "pause", "resume" or "step". False with `error` when refused.
  virtual bool Control(const std::string& action, std::string* error) = 0;
  // A page connected (+1) or left (-1) the update stream.
  virtual void ClientsChanged(int delta) = 0;
};

// Sorted by stamp, one pose per stamp (the first).
Trajectory SortedUnique(Trajectory trajectory);

// The ground-truth positions in the estimate's frame, by the TUM tools' rigid alignment of the
// associated positions (eval/ate.h); empty when fewer than 3 poses associate. Both sorted by
// stamp without duplicates.
std::vector<Eigen::Vector3d> GroundTruthInEstimateFrame(const Trajectory& ground_truth,
                                                        const Trajectory& estimate);

}  // namespace detslam
