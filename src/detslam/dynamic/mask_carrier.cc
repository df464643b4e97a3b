#include "detslam/dynamic/mask_carrier.h"

#include <chrono>

#include "detslam/core/check.h"

namespace detslam {

MaskCarrier::MaskCarrier(MaskPropagationOptions options) : propagator_(options) {}

void MaskCarrier::Publish(int64_t index, const cv::Mat& gray, std::vector<Instance> instances) {
  DETSLAM_CHECK(gray.type() == CV_8UC1);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (newest_ && newest_->index >= index) return;
    newest_ = Published{index, gray, std::move(instances)};
    ++published_;
  }
  changed_.notify_all();
}

std::optional<CarriedInstances> MaskCarrier::Carry(int64_t index, const cv::Mat& gray) {
  DETSLAM_CHECK_MSG(index > carried_, "MaskCarrier::Carry: frames must come in input order");
  const auto t0 = std::chrono::steady_clock::now();
  std::optional<Published> fresh;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    // Newer instances than the propagator's, segmented on this frame or an earlier one. The image
    // is copied under the lock: the publisher releases the shared buffer under the same lock when
    // it publishes the next one (cv::Mat's reference count is invisible to ThreadSanitizer).
    if (newest_ && newest_->index > source_ && newest_->index <= index) {
      fresh = Published{newest_->index, newest_->gray.clone(), newest_->instances};
      for (Instance& in : fresh->instances) in.mask = in.mask.clone();
    }
  }
  if (fresh) {
    propagator_.Reset(fresh->gray, fresh->instances);
    source_ = carried_ = fresh->index;
    source_instances_ = std::move(fresh->instances);
  }
  if (source_ < 0) return std::nullopt;
  CarriedInstances out;
  out.source = source_;
  out.age = static_cast<int>(index - source_);
  if (index == source_) {
    out.instances = source_instances_;
  } else {
    out.instances = propagator_.Propagate(gray, static_cast<int>(index - carried_));
  }
  carried_ = index;
  out.carry_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

bool MaskCarrier::WaitFor(int64_t index) {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [&] { return closed_ || (newest_ && newest_->index >= index); });
  return newest_ && newest_->index >= index;
}

void MaskCarrier::Close() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    closed_ = true;
  }
  changed_.notify_all();
}

int64_t MaskCarrier::published() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return published_;
}

}  // namespace detslam
