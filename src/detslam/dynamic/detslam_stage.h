// The Det-SLAM stage: everything detslam does about dynamic objects, in one object with one
// options struct, turning a frame plus its instances into one label per keypoint, computed once.
//  - Loader side (Segment; not const, frames in input order): the segmenter on every
//    `segment_every`-th frame, lost instances carried forward (InstanceMemory), masks moved by
//    optical flow in between (MaskPropagator).
//  - Extraction side (Extract; const, may run in another thread): the frame's instances are
//    rasterised once (DynamicRegions: dilated masks, depth intervals), their pixel form goes to
//    the ORB extractor (premask), each keypoint's depth is sampled once and every keypoint gets its
//    label (mask step, depth step).
//  - The geometric check for movers the segmenter missed (LabelMovers, mover_check.h, with this
//    stage's `geometric` options) needs the tracked pose: the tracker calls it on each frame.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "detslam/dynamic/dynamic_filter.h"
#include "detslam/dynamic/geometric_check.h"
#include "detslam/dynamic/instance_memory.h"
#include "detslam/dynamic/mask_propagation.h"
#include "detslam/features/orb_extractor.h"
#include "detslam/segmentation/segmenter.h"

namespace detslam {

struct DetSlamOptions {
  DynamicFilterOptions filter;  // mask step and depth step (Det-SLAM eqs. 1-6)
  bool premask = true;          // also drop dynamic corners before the ORB spatial distribution
  int memory_frames = 3;        // carry lost instances forward this many frames (0.1 s)
  int depth_track_frames = 30;  // follow lost instances in depth for this many frames (0 = off)
  int segment_every = 1;        // segmenter on every k-th frame; masks follow the flow in between
  // Asynchronous segmentation (camera-rate mode): a frame whose masks were segmented on a frame
  // more than this many input frames older does not become a keyframe (no new map points from
  // stale masks); the tracker asks again on the next frame. Frames with their own masks have age 0.
  int keyframe_max_mask_age = 6;  // chosen on walking_xyz tuning seeds 1-3 (bench_realtime.sh)
  // ... but only while the frame tracks at least keyframe_defer_min_inliers map points (about 3x
  // the 30 that make local-map tracking succeed), and at most keyframe_max_wait input frames after
  // the first frame that asked for it: then the keyframe is made with the masks it has. A map
  // starved of keyframes loses tracking: on loop_long (tuning seed 1), where the camera turns
  // fast, the inliers fell from 86 to 34 over the 5 frames of a deferral and tracking failed.
  int keyframe_defer_min_inliers = 100;
  int keyframe_max_wait = 6;  // 0.2 s at 30 Hz
  // Keyframes cleaned by their own masks (asynchronous segmentation only): when the detector's
  // result for a frame that became a keyframe (with carried masks) comes, the keyframe's keypoints
  // are labelled by it; the points the keyframe made on objects are erased, older points lose its
  // view. Chosen on walking tuning seeds 1-6 (--simulate-camera-rate-masks 5, and live runs): it
  // removes the runs where the tracker followed a person the carried masks missed, at a slightly
  // higher median error (README).
  bool keyframe_clean_own_masks = true;
  MaskPropagationOptions propagation;  // how masks move between segmented frames
  MoverCheckOptions geometric;         // geometric check for movers the segmenter missed (tracker)

  bool Check(std::string* error) const;
};

// The instances of one frame from the loader side.
struct FrameInstances {
  std::vector<Instance> instances;
  bool segmented = false;      // the stage ran for this frame (a segmenter is set)
  double segmentation_ms = 0;  // time of the segmenter (or the mask propagation)
};

// Extraction output with the stage's decision per keypoint.
struct LabelledKeypoints {
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;                // one row per keypoint
  std::vector<float> depth;           // per keypoint (SampleKeypointDepth), <= 0 unknown
  std::vector<KeypointLabel> labels;  // per keypoint: kStatic, kDynamicMask or kDynamicDepth
  int instances_used = 0;             // dynamic instances the filter used
  // CV_8UC1, non-zero where keypoints are withheld (the ignore mask and the dynamic regions, as
  // Label decides them); empty when nothing is.
  cv::Mat withheld;
};

class DetSlamStage {
 public:
  // `segmenter` may be null: then Segment reports no instances and Extract labels nothing.
  DetSlamStage(DetSlamOptions options, Segmenter* segmenter);

  // Loader side: the dynamic instances (those the filter uses) of the frame `input` describes
  // (`gray`: its CV_8UC1 image, for the mask propagation). Frames must come in input order.
  FrameInstances Segment(const SegmenterInput& input, const cv::Mat& gray);

  // Asynchronous segmentation's thread (frames in input order, not necessarily every frame): the
  // segmenter and the instance memory on the frame, no propagation (MaskCarrier carries the result
  // to the frames that did not wait for it).
  FrameInstances Detect(const SegmenterInput& input);

  // Extraction side: ORB keypoints of `gray` with their depth and labels. `instances`: null when
  // the frame was not segmented (every keypoint static). `ignore_mask`: empty or CV_8UC1,
  // non-zero = no keypoints there. `pyramid`: null, or extractor.Prepare(gray) computed earlier.
  LabelledKeypoints Extract(const OrbExtractor& extractor, const cv::Mat& gray,
                            const cv::Mat& depth_m, const cv::Mat& ignore_mask,
                            const std::vector<Instance>* instances,
                            const OrbPyramid* pyramid = nullptr) const;
  // The regions Extract would label a frame's keypoints with (mask step and depth step), for
  // labelling keypoints extracted earlier (keyframes cleaned by their own masks). `depth_m`: the
  // frame's depth (CV_32FC1 metres, 0 = missing) of `image_size`.
  DynamicRegions Regions(const std::vector<Instance>& instances, const cv::Mat& depth_m,
                         const cv::Size& image_size) const;

 private:
  // The instances the filter acts on (DynamicFilterOptions::Uses): the others (static classes,
  // low scores) are dropped before the memory, the propagation and the keyframe masks, which
  // would spend time on them for nothing (a YOLOX frame of a room has books, chairs, screens).
  std::vector<Instance> Used(std::vector<Instance> instances) const;

  DetSlamOptions options_;
  Segmenter* segmenter_;
  InstanceMemory memory_;  // detections lost for a frame or two
  int64_t last_detected_index_ = -1;  // Detect(): the previous frame it ran on
  MaskPropagator propagator_;  // masks between segmented frames (segment_every > 1)
};

}  // namespace detslam
