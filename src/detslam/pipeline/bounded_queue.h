// A bounded multi-producer/multi-consumer queue for pipeline stages. Push blocks while full, Pop
// blocks while empty; Close() ends the stream: Push then fails and Pop drains what is left and
// then returns std::nullopt. No polling: waits on condition variables.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <mutex>
#include <optional>

namespace detslam {

template <typename T>
class BoundedQueue {
 public:
  explicit BoundedQueue(size_t capacity) : capacity_(capacity == 0 ? 1 : capacity) {}

  // Returns false if the queue was closed (the item is dropped).
  bool Push(T item) {
    std::unique_lock<std::mutex> lock(mutex_);
    not_full_.wait(lock, [&] { return closed_ || items_.size() < capacity_; });
    if (closed_) return false;
    items_.push_back(std::move(item));
    not_empty_.notify_one();
    return true;
  }

  // Never blocks: when the queue is full its oldest item makes room and is handed to *dropped
  // (a camera's newest-frame buffer). Returns false if the queue was closed (the item is dropped).
  bool PushDroppingOldest(T item, std::optional<T>* dropped) {
    std::lock_guard<std::mutex> lock(mutex_);
    dropped->reset();
    if (closed_) return false;
    if (items_.size() >= capacity_) {
      *dropped = std::move(items_.front());
      items_.pop_front();
    }
    items_.push_back(std::move(item));
    not_empty_.notify_one();
    return true;
  }

  // Next item, or nullopt once the queue is closed and empty.
  std::optional<T> Pop() {
    std::unique_lock<std::mutex> lock(mutex_);
    not_empty_.wait(lock, [&] { return closed_ || !items_.empty(); });
    if (items_.empty()) return std::nullopt;
    T item = std::move(items_.front());
    items_.pop_front();
    not_full_.notify_one();
    return item;
  }

  void Close() {
    std::lock_guard<std::mutex> lock(mutex_);
    closed_ = true;
    not_empty_.notify_all();
    not_full_.notify_all();
  }

 private:
  const size_t capacity_;
  std::mutex mutex_;
  std::condition_variable not_empty_, not_full_;
  std::deque<T> items_;
  bool closed_ = false;
};

}  // namespace detslam
