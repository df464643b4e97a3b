#include "detslam/pipeline/keyframe_mask_recorder.h"

#include <algorithm>

namespace detslam {

KeyframeMaskRecorder::KeyframeMaskRecorder(const DynamicFilterOptions& filter, int lookahead)
    : filter_(filter), lookahead_(std::max(0, lookahead)) {}

void KeyframeMaskRecorder::AddFrame(int64_t frame, bool keyframe,
                                    const std::vector<Instance>& instances,
                                    const cv::Mat& depth_m) {
  if (!keyframe && pending_.empty()) return;
  cv::Mat mask;
  if (!instances.empty()) mask = DynamicIgnoreMask(instances, depth_m, depth_m.size(), filter_);
  for (Pending& p : pending_) {
    if (frame <= p.last && !mask.empty() && mask.size() == p.mask.size())
      cv::bitwise_or(p.mask, mask, p.mask);
  }
  if (keyframe) {
    pending_.push_back({static_cast<size_t>(frame), frame + lookahead_,
                        mask.empty() ? cv::Mat(depth_m.size(), CV_8UC1, cv::Scalar(0)) : mask.clone()});
  }
  const auto done = std::stable_partition(pending_.begin(), pending_.end(),
                                          [&](const Pending& p) { return p.last > frame; });
  for (auto it = done; it != pending_.end(); ++it) Store(*it);
  pending_.erase(done, pending_.end());
}

KeyframeMasks KeyframeMaskRecorder::Finish() {
  for (const Pending& p : pending_) Store(p);
  pending_.clear();
  return std::move(masks_);
}

void KeyframeMaskRecorder::Store(const Pending& p) {
  if (cv::countNonZero(p.mask) > 0) masks_[p.frame] = EncodeKeyframeMask(p.mask);
}

}  // namespace detslam
