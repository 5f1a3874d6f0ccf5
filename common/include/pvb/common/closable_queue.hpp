#pragma once
// A blocking FIFO between threads that can be closed: the local-mapping and
// dense-mapping workers' keyframe queues (unbounded) and a scenario run's
// producer/consumer queues (bounded).  pop() waits for an item, push() for
// room when the queue has a capacity; no polling.  close() wakes both sides:
// push() then refuses items and pop() drains what is left, then returns
// nullopt.
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <mutex>
#include <optional>

namespace pvb {

template <typename T>
class ClosableQueue {
 public:
  /// capacity 0: unbounded (push() never waits).
  explicit ClosableQueue(std::size_t capacity = 0) : capacity_(capacity) {}

  /// Waits for room (bounded queues), then queues the item.  Returns false,
  /// dropping the item, when the queue is or becomes closed.
  bool push(T item) {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      not_full_.wait(lock, [&] { return closed_ || capacity_ == 0 || items_.size() < capacity_; });
      if (closed_) return false;
      items_.push_back(std::move(item));
    }
    not_empty_.notify_one();
    return true;
  }

  /// Waits for an item; nullopt once the queue is closed and drained.
  std::optional<T> pop() {
    std::optional<T> item;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      not_empty_.wait(lock, [&] { return closed_ || !items_.empty(); });
      if (items_.empty()) return std::nullopt;
      item.emplace(std::move(items_.front()));
      items_.pop_front();
    }
    not_full_.notify_one();
    return item;
  }

  /// No more items: wakes every waiting push() and pop().
  void close() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closed_ = true;
    }
    not_full_.notify_all();
    not_empty_.notify_all();
  }

  /// Closes the queue and drops the items still in it (a consumer that stops early).
  void close_and_clear() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closed_ = true;
      items_.clear();
    }
    not_full_.notify_all();
    not_empty_.notify_all();
  }

  bool closed() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return closed_;
  }
  std::size_t size() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return items_.size();
  }
  /// 0 for an unbounded queue.
  std::size_t capacity() const { return capacity_; }

 private:
  const std::size_t capacity_;
  mutable std::mutex mutex_;
  std::condition_variable not_full_, not_empty_;
  std::deque<T> items_;
  bool closed_ = false;
};

}  // namespace pvb
