#include "detslam/pipeline/slam_system.h"

#include <chrono>
#include <cmath>
#include <sstream>

#include "detslam/core/check.h"

namespace detslam {
namespace {

double MsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

bool SlamOptions::Check(std::string* error) const {
  std::string e1, e2, e3, e4, e5;
  const bool ok = orb.Check(&e1) & tracker.Check(&e2) & mapper.Check(&e3) & dynamic.Check(&e4) & loop.Check(&e5);
  if (error) *error = e1 + e2 + e3 + e4 + e5;
  return ok;
}

ScaleInfo MakeScaleInfo(const OrbExtractor& extractor) {
  ScaleInfo s;
  s.scale_factors = extractor.scale_factors();
  s.level_sigma2 = extractor.level_sigma2();
  s.inv_level_sigma2 = extractor.inv_level_sigma2();
  s.log_scale_factor = std::log(extractor.options().scale_factor);
  return s;
}

SlamSystem::SlamSystem(const PinholeCamera& camera, const SlamOptions& options)
    : camera_(camera),
      options_(options),
      extractor_(options.orb),
      map_(MakeScaleInfo(extractor_)),
      tracker_(camera, options.tracker, &map_),
      mapper_(camera, options.mapper, &map_),
      loop_closer_(camera, options.loop, &map_) {
  std::string error;
  DETSLAM_CHECK_MSG(camera_.Check(&error), error);
  if (options_.mapping_thread) {
    keyframe_queue_ = std::make_unique<BoundedQueue<KeyFrameId>>(8);
    mapping_thread_ = std::thread([this] { MappingLoop(); });
  }
}

SlamSystem::~SlamSystem() { Finish(); }

void SlamSystem::Finish() {
  if (!mapping_thread_.joinable()) return;
  keyframe_queue_->Close();
  mapping_thread_.join();
}

void SlamSystem::MappingLoop() {
  while (std::optional<KeyFrameId> kf = keyframe_queue_->Pop()) {
    FrameReport unused;
    MapKeyFrame(*kf, &unused);
  }
}

void SlamSystem::MapKeyFrame(KeyFrameId kf, FrameReport* report) {
  const auto t0 = std::chrono::steady_clock::now();
  const LocalMappingSummary s = mapper_.ProcessKeyFrame(kf, options_.mapping_thread ? &map_mutex_ : nullptr);
  std::unique_lock<std::mutex> lock;
  if (options_.mapping_thread) lock = std::unique_lock<std::mutex>(map_mutex_);
  for (const ErasedKeyFrame& e : s.erased_keyframes) {
    erased_[e.id] = e;
    tracker_.OnKeyFrameErased(e.id);
  }
  const LoopClosingResult loop = loop_closer_.Process(kf);
  if (loop.closed) {
    tracker_.OnLoopClosed(loop.old_poses);
    report->loop_closed = true;
  }
  report->timings.mapping_ms = MsSince(t0);
  mapping_times_ms_.push_back(report->timings.mapping_ms);
}

FrameReport SlamSystem::ProcessFrame(int64_t index, Timestamp stamp, const cv::Mat& gray,
                                     const cv::Mat& depth_m, const cv::Mat& ignore_mask) {
  FrameReport report;
  Frame frame = ExtractFrame(index, stamp, gray, depth_m, ignore_mask, &report);
  TrackFrame(std::move(frame), &report);
  return report;
}

Frame SlamSystem::ExtractFrame(int64_t index, Timestamp stamp, const cv::Mat& gray,
                               const cv::Mat& depth_m, const cv::Mat& ignore_mask,
                               FrameReport* report, const std::vector<Instance>* instances) const {
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  cv::Mat mask = ignore_mask;
  if (instances != nullptr && options_.dynamic_premask && !instances->empty()) {
    cv::Mat dyn = DynamicIgnoreMask(*instances, depth_m, gray.size(), options_.dynamic);
    if (mask.empty()) {
      mask = dyn;
    } else {
      cv::bitwise_or(mask, dyn, mask);
    }
  }
  extractor_.Extract(gray, mask, &keypoints, &descriptors);
  std::vector<cv::KeyPoint> rejected;
  std::vector<KeypointLabel> rejected_labels;
  if (instances != nullptr) {
    std::vector<float> kp_depth(keypoints.size(), -1.0f);
    for (size_t i = 0; i < keypoints.size() && !depth_m.empty(); ++i) {
      const int u = static_cast<int>(std::lround(keypoints[i].pt.x));
      const int v = static_cast<int>(std::lround(keypoints[i].pt.y));
      if (u >= 0 && v >= 0 && u < depth_m.cols && v < depth_m.rows) kp_depth[i] = depth_m.at<float>(v, u);
    }
    std::vector<KeypointLabel> labels(keypoints.size(), KeypointLabel::kStatic);
    const DynamicFilterStats stats = LabelDynamicKeypoints(keypoints, kp_depth, *instances, depth_m, options_.dynamic, &labels);
    report->dynamic_instances = stats.instances_used;
    std::vector<cv::KeyPoint> kept;
    cv::Mat kept_desc;
    for (size_t i = 0; i < keypoints.size(); ++i) {
      if (labels[i] == KeypointLabel::kStatic) {
        kept.push_back(keypoints[i]);
        kept_desc.push_back(descriptors.row(static_cast<int>(i)));
      } else {
        rejected.push_back(keypoints[i]);
        rejected_labels.push_back(labels[i]);
      }
    }
    keypoints = std::move(kept);
    descriptors = kept_desc;
    report->rejected_keypoints = static_cast<int>(rejected.size());
  }
  Frame frame;
  frame.index = index;
  frame.stamp = stamp;
  auto features = BuildFrameFeatures(camera_, std::move(keypoints), descriptors, depth_m);
  features->rejected_keypoints = std::move(rejected);
  features->rejected_labels = std::move(rejected_labels);
  frame.features = std::move(features);
  report->index = index;
  report->stamp = stamp;
  report->num_keypoints = static_cast<int>(frame.size());
  report->timings.extraction_ms = MsSince(t0);
  return frame;
}

void SlamSystem::TrackFrame(Frame frame, FrameReport* report) {
  auto t0 = std::chrono::steady_clock::now();
  std::unique_lock<std::mutex> lock;
  if (options_.mapping_thread) lock = std::unique_lock<std::mutex>(map_mutex_);
  const size_t kfs_before = map_.NumKeyFrames();
  report->tracking = tracker_.Track(&frame);
  KeyFrameId new_kf = kNoKeyFrame;
  if (report->tracking.pose_valid && report->tracking.need_keyframe) new_kf = tracker_.CreateKeyFrame(&frame);
  if (map_.NumKeyFrames() > kfs_before && new_kf == kNoKeyFrame) new_kf = tracker_.reference_keyframe();
  report->timings.tracking_ms = MsSince(t0);

  if (report->tracking.pose_valid) {
    const KeyFrameId ref = frame.reference_keyframe != kNoKeyFrame ? frame.reference_keyframe : tracker_.reference_keyframe();
    tracked_.push_back({frame.stamp, ref, *frame.cam_from_world * map_.keyframe(ref).cam_from_world.Inverse()});
  }
  if (new_kf != kNoKeyFrame) {
    report->keyframe = true;
    if (options_.mapping_thread) {
      lock.unlock();
      keyframe_queue_->Push(new_kf);
    } else {
      MapKeyFrame(new_kf, report);
    }
  }
}

Rigid3d SlamSystem::ReferenceWorldFromCam(KeyFrameId id, const Rigid3d& cam_from_ref) const {
  // Walk up through erased keyframes to one that still exists.
  Rigid3d cam_from_kf = cam_from_ref;
  KeyFrameId kf = id;
  for (int guard = 0; !map_.HasKeyFrame(kf) && guard < 100000; ++guard) {
    auto it = erased_.find(kf);
    DETSLAM_CHECK_MSG(it != erased_.end(), "keyframe " << kf << " vanished without a record");
    cam_from_kf = cam_from_kf * it->second.cam_from_parent;
    kf = it->second.parent;
  }
  return (cam_from_kf * map_.keyframe(kf).cam_from_world).Inverse();
}

Trajectory SlamSystem::FrameTrajectory() const {
  Trajectory out;
  out.reserve(tracked_.size());
  for (const TrackedFrame& t : tracked_) out.push_back({t.stamp, ReferenceWorldFromCam(t.reference, t.cam_from_ref)});
  return out;
}

Trajectory SlamSystem::KeyFrameTrajectory() const {
  Trajectory out;
  for (const auto& [id, kf] : map_.keyframes()) out.push_back({kf.stamp, kf.cam_from_world.Inverse()});
  return out;
}

}  // namespace detslam
