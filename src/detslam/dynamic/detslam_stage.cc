#include "detslam/dynamic/detslam_stage.h"

#include <algorithm>
#include <chrono>

#include "detslam/core/check.h"

namespace detslam {

bool DetSlamOptions::Check(std::string* error) const {
  std::string e;
  if (!filter.Check(&e)) {
    if (error) *error = "dynamic filter: " + e;
    return false;
  }
  if (!geometric.Check(&e)) {
    if (error) *error = "geometric check: " + e;
    return false;
  }
  if (!propagation.Check(&e)) {
    if (error) *error = "mask propagation: " + e;
    return false;
  }
  if (memory_frames < 0 || depth_track_frames < 0 || segment_every < 1 || keyframe_max_mask_age < 0 ||
      keyframe_max_wait < 0 || keyframe_defer_min_inliers < 0) {
    if (error)
      *error =
          "memory_frames and depth_track_frames must be >= 0, segment_every >= 1, keyframe_max_mask_age >= 0 and "
          "keyframe_max_wait and keyframe_defer_min_inliers >= 0";
    return false;
  }
  if (error) error->clear();
  return true;
}

DetSlamStage::DetSlamStage(DetSlamOptions options, Segmenter* segmenter)
    : options_(std::move(options)),
      segmenter_(segmenter),
      memory_(options_.memory_frames, InstanceMemory::kDefaultMinIou, options_.depth_track_frames),
      propagator_(options_.propagation) {
  std::string error;
  DETSLAM_CHECK_MSG(options_.Check(&error), "invalid DetSlamOptions: " << error);
}

namespace {
// Runs `segment` (returning the frame's instances) and times it.
template <typename SegmentFn>
FrameInstances Timed(SegmentFn&& segment) {
  FrameInstances out;
  const auto t0 = std::chrono::steady_clock::now();
  out.instances = segment();
  out.segmented = true;
  out.segmentation_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return out;
}
}  // namespace

std::vector<Instance> DetSlamStage::Used(std::vector<Instance> instances) const {
  instances.erase(std::remove_if(instances.begin(), instances.end(),
                                 [&](const Instance& i) { return !options_.filter.Uses(i); }),
                  instances.end());
  return instances;
}

FrameInstances DetSlamStage::Segment(const SegmenterInput& input, const cv::Mat& gray) {
  if (segmenter_ == nullptr) return {};
  return Timed([&] {
    const int every = options_.segment_every;
    if (every > 1 && input.index % every != 0) return propagator_.Propagate(gray);
    std::vector<Instance> instances = memory_.Update(Used(segmenter_->Segment(input)), input.depth_m, every);
    if (every > 1) propagator_.Reset(gray, instances);
    return instances;
  });
}

FrameInstances DetSlamStage::Detect(const SegmenterInput& input) {
  if (segmenter_ == nullptr) return {};
  // The detector picks its frames (it may skip some): the memory's depth tracking counts frames.
  const int elapsed = last_detected_index_ >= 0 && input.index > last_detected_index_
                          ? static_cast<int>(input.index - last_detected_index_)
                          : 1;
  last_detected_index_ = input.index;
  return Timed([&] { return memory_.Update(Used(segmenter_->Segment(input)), input.depth_m, elapsed); });
}

DynamicRegions DetSlamStage::Regions(const std::vector<Instance>& instances,
                                     const cv::Mat& depth_m, const cv::Size& image_size) const {
  return DynamicRegions::Build(instances, depth_m, image_size, options_.filter);
}

LabelledKeypoints DetSlamStage::Extract(const OrbExtractor& extractor, const cv::Mat& gray,
                                        const cv::Mat& depth_m, const cv::Mat& ignore_mask,
                                        const std::vector<Instance>* instances,
                                        const OrbPyramid* pyramid) const {
  LabelledKeypoints out;
  DynamicRegions regions;
  if (instances != nullptr) {
    regions = Regions(*instances, depth_m, gray.size());
  }
  cv::Mat withheld = ignore_mask;
  if (instances != nullptr && !instances->empty()) {
    cv::Mat dynamic = regions.IgnoreMask(depth_m);
    if (ignore_mask.empty()) {
      withheld = std::move(dynamic);
    } else {
      withheld = cv::Mat();  // a new buffer: the caller's mask stays as it was
      cv::bitwise_or(ignore_mask, dynamic, withheld);
    }
  }
  const cv::Mat& extraction_mask = options_.premask ? withheld : ignore_mask;
  if (pyramid != nullptr) {
    extractor.Extract(*pyramid, extraction_mask, &out.keypoints, &out.descriptors);
  } else {
    extractor.Extract(gray, extraction_mask, &out.keypoints, &out.descriptors);
  }
  out.withheld = withheld;
  out.depth = SampleKeypointDepth(out.keypoints, depth_m);
  out.labels.assign(out.keypoints.size(), KeypointLabel::kStatic);
  if (instances != nullptr) {
    out.instances_used = regions.Label(out.keypoints, out.depth, &out.labels).instances_used;
  }
  return out;
}

}  // namespace detslam
