// Instance segmentation of (potentially) dynamic objects: image (and depth) in, instances out.
// Backends: OpenCV-dnn detector + per-box person mask, precomputed masks on disk, the synthetic
// generator's ground truth, or none.
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "detslam/core/timestamp.h"

namespace detslam {

struct Instance {
  int class_id = 0;           // COCO class index (0 = person)
  std::string class_name;     // e.g. "person"
  float score = 0.0f;         // detector confidence in [0, 1]
  cv::Rect box;               // pixels, clipped to the image
  cv::Mat mask;               // CV_8UC1, image size, non-zero = object pixel (may be empty: box only)
};

// The classes treated as dynamic unless Dynamic.Classes says otherwise: the default of the dynamic
// filter (DynamicFilterOptions::dynamic_classes) and of the classes the segmenters return.
inline std::vector<std::string> DefaultDynamicClasses() { return {"person"}; }

struct SegmenterInput {
  int64_t index = 0;          // frame index in the sequence
  Timestamp stamp;            // colour image stamp
  cv::Mat bgr;                // CV_8UC3
  cv::Mat depth_m;            // CV_32FC1 metres (0 = missing); may be empty
};

class Segmenter {
 public:
  virtual ~Segmenter() = default;
  // Instances found in the frame (the classes the backend returns; the Det-SLAM stage keeps those
  // the dynamic filter uses). Throws InputError for unreadable inputs named in the message.
  virtual std::vector<Instance> Segment(const SegmenterInput& input) = 0;
  virtual std::string name() const = 0;
  // Runs the backend once on `input` and forgets the result and any state it left (e.g. a network
  // that allocates its layers on the first call), so that the first real frame is not slower than
  // the others. Default: nothing to warm up.
  virtual void WarmUp(const SegmenterInput& input) { (void)input; }
};

}  // namespace detslam
