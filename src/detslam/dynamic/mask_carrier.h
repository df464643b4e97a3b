// Asynchronous segmentation's hand-over between the segmentation thread and the frames that do
// not wait for it: the segmentation thread publishes the instances of the newest frame it
// segmented; the extraction side carries the newest published instances to each later frame with
// the mask propagation (median optical flow, masks grown with their age in input frames) and
// knows their age. Publish and Carry may run in different threads; Carry sees the frames in input
// order.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <vector>

#include "detslam/dynamic/mask_propagation.h"
#include "detslam/segmentation/segmenter.h"

namespace detslam {

// The instances given to one frame.
struct CarriedInstances {
  std::vector<Instance> instances;
  int64_t source = -1;  // the input frame they were segmented on
  int age = 0;          // input frames from `source` to this frame (0: its own segmentation)
  double carry_ms = 0;  // time of the propagation
};

class MaskCarrier {
 public:
  explicit MaskCarrier(MaskPropagationOptions options = {});

  // Segmentation side: the instances of input frame `index` (its CV_8UC1 image `gray`). A result
  // older than one already published is ignored.
  void Publish(int64_t index, const cv::Mat& gray, std::vector<Instance> instances);

  // Extraction side, frames in input order: the newest published instances carried to frame
  // `index` (image `gray`). Nothing when no instances were published yet.
  std::optional<CarriedInstances> Carry(int64_t index, const cv::Mat& gray);

  // Waits until instances of frame `index` or a later one are published, or Close(). Returns
  // whether they were.
  bool WaitFor(int64_t index);
  // Ends every wait (a stage failed or the run stops).
  void Close();

  // Frames whose instances were published.
  int64_t published() const;

 private:
  struct Published {
    int64_t index = -1;
    cv::Mat gray;
    std::vector<Instance> instances;
  };

  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::optional<Published> newest_;  // guarded by mutex_
  int64_t published_ = 0;            // guarded by mutex_
  bool closed_ = false;              // guarded by mutex_

  // Extraction side only.
  MaskPropagator propagator_;
  int64_t source_ = -1;   // the frame the propagator was reset on
  int64_t carried_ = -1;  // the last frame carried to
  std::vector<Instance> source_instances_;  // for a frame carried to its own segmentation
};

}  // namespace detslam
