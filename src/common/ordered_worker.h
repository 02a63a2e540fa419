#pragma once
// OrderedWorker: a thread of its own that handles items one at a time, in the order they were
// queued, behind a queue of bounded length. The output writers (formats/outputs.cpp) and the
// frame thread (bake/frame_thread.h) are two. The first exception the handler throws stops
// the worker: the items queued behind it are dropped, and the producer gets the exception back
// from its next call. One producer thread.
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <utility>

namespace treeanim {

template <typename Item>
class OrderedWorker {
 public:
  // Starts the thread: `start` runs there first (its priority, its thread count), then
  // `handle` for each item. At most `capacity` (> 0) items wait beside the one in hand. An
  // exception from `start` is the worker's first, as one from `handle` is.
  OrderedWorker(size_t capacity, std::function<void()> start, std::function<void(Item&)> handle)
      : capacity_(capacity > 0 ? capacity : throw std::logic_error("OrderedWorker: a queue of no item")),
        start_(std::move(start)),
        handle_(std::move(handle)),
        thread_(&OrderedWorker::run, this) {}
  // stop(): a producer unwinding from an error has its own to report.
  ~OrderedWorker() { stop(); }
  OrderedWorker(const OrderedWorker&) = delete;
  OrderedWorker& operator=(const OrderedWorker&) = delete;

  // Waits for room, then queues `item`. Rethrows the first exception of the handler; after
  // close() or stop(), nothing would handle the item: a logic_error.
  void push(Item item) {
    {
      std::unique_lock lock(mutex_);
      changed_.wait(lock, [&] { return error_ || queue_.size() < capacity_; });
      if (error_) std::rethrow_exception(error_);
      if (closing_ || stopping_) throw std::logic_error("OrderedWorker::push after close() or stop()");
      queue_.push_back(std::move(item));
    }
    changed_.notify_all();
  }

  // Returns once every item queued is handled. Rethrows the first exception of the handler.
  void drain() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return error_ || (queue_.empty() && !busy_); });
    if (error_) std::rethrow_exception(error_);
  }

  // Handles every item queued, then ends the thread. Rethrows the first exception of the handler.
  void close() {
    {
      std::lock_guard lock(mutex_);
      closing_ = true;
    }
    changed_.notify_all();
    if (thread_.joinable()) thread_.join();
    std::lock_guard lock(mutex_);
    if (error_) std::rethrow_exception(error_);
  }

  // Drops the items not yet begun, lets the one in hand end, and ends the thread. Never throws.
  void stop() noexcept {
    {
      std::lock_guard lock(mutex_);
      stopping_ = true;
      queue_.clear();
    }
    changed_.notify_all();
    if (thread_.joinable()) thread_.join();
  }

 private:
  void run() {
    try {
      if (start_) start_();
    } catch (...) {
      std::lock_guard lock(mutex_);
      error_ = std::current_exception();
      queue_.clear();
    }
    changed_.notify_all();
    for (;;) {
      Item item;
      {
        std::unique_lock lock(mutex_);
        changed_.wait(lock, [&] { return error_ || stopping_ || closing_ || !queue_.empty(); });
        if (error_ || stopping_ || queue_.empty()) return;
        item = std::move(queue_.front());
        queue_.pop_front();
        busy_ = true;
      }
      changed_.notify_all();  // room in the queue
      std::exception_ptr error;
      try {
        handle_(item);
      } catch (...) {
        error = std::current_exception();
      }
      {
        std::lock_guard lock(mutex_);
        busy_ = false;
        if (error) {
          error_ = error;
          queue_.clear();  // nothing after a failed item is handled
        }
      }
      changed_.notify_all();
      if (error) return;
    }
  }

  const size_t capacity_;
  const std::function<void()> start_;
  const std::function<void(Item&)> handle_;
  std::mutex mutex_;
  std::condition_variable changed_;  // an item queued or taken, one handled, an error, closing or stopping
  std::deque<Item> queue_;
  bool busy_ = false, closing_ = false, stopping_ = false;
  std::exception_ptr error_;
  std::thread thread_;  // last: it starts once everything above is built
};

}  // namespace treeanim
