// Records, for the dense map and keyframe_masks/, the pixels the Det-SLAM stage removes from each
// keyframe: the pixel form of the filter (DynamicIgnoreMask: the dilated instance masks and the
// depth step inside each box) of the keyframe's own frame, united with those of the frames up to
// `lookahead` indices later. The instance memory already carries a lost detection forward for that many
// frames; the dense map is fused after the run, so it can also look forward, which covers a person
// the segmenter finds only a frame or two after a keyframe (e.g. cut by the image border at the
// first frame). Masks are kept PNG-encoded (a few kB each).
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "detslam/dense/dense_fusion.h"
#include "detslam/dynamic/dynamic_filter.h"
#include "detslam/segmentation/segmenter.h"

namespace detslam {

class KeyframeMaskRecorder {
 public:
  KeyframeMaskRecorder(const DynamicFilterOptions& filter, int lookahead);

  // Every processed frame, in input order: its index, whether it became a keyframe, its dynamic
  // instances (empty when none or not segmented) and its depth (CV_32FC1 metres).
  void AddFrame(int64_t frame, bool keyframe, const std::vector<Instance>& instances,
                const cv::Mat& depth_m);
  // The masks of every keyframe with removed pixels (keyframes still waiting for their next
  // frames are completed with what there is). Call once, after the last frame.
  KeyframeMasks Finish();

 private:
  struct Pending {
    size_t frame;
    int64_t last;   // the last frame index whose mask is united with it
    cv::Mat mask;   // CV_8UC1, 255 = removed
  };
  void Store(const Pending& p);

  DynamicFilterOptions filter_;
  int lookahead_;
  std::vector<Pending> pending_;
  KeyframeMasks masks_;
};

}  // namespace detslam
