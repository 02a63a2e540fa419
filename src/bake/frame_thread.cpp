#include "bake/frame_thread.h"

#include <omp.h>

#include <utility>

namespace treeanim {

FrameThread::FrameThread(Work work) : work_(std::move(work)), thread_(&FrameThread::run, this) {}

FrameThread::~FrameThread() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
    has_queued_ = false;
  }
  changed_.notify_all();
  thread_.join();
}

void FrameThread::submit(const SimState& state, bool velocities, long long frame) {
  {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return error_ || !has_queued_; });
    if (error_) std::rethrow_exception(error_);
  }
  // The slot is free: the thread only reads it once has_queued_ is set.
  queued_.positions = state.positions;
  if (velocities) queued_.velocities = state.velocities;
  else queued_.velocities.resize(3, 0);
  queued_.cluster_rotations = state.cluster_rotations;
  queued_.leaf_attached = state.leaf_attached;
  queued_.time = state.time;
  {
    std::lock_guard lock(mutex_);
    queued_frame_ = frame;
    has_queued_ = true;
  }
  changed_.notify_all();
}

void FrameThread::finish() {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return error_ || (!has_queued_ && !busy_); });
  if (error_) std::rethrow_exception(error_);
}

void FrameThread::run() {
  omp_set_num_threads(1);
  for (;;) {
    long long frame = 0;
    {
      std::unique_lock lock(mutex_);
      changed_.wait(lock, [&] { return stopping_ || has_queued_; });
      if (stopping_) return;
      std::swap(queued_, in_hand_);
      frame = queued_frame_;
      has_queued_ = false;
      busy_ = true;
    }
    changed_.notify_all();
    std::exception_ptr error;
    try {
      work_(in_hand_, frame);
    } catch (...) {
      error = std::current_exception();
    }
    {
      std::lock_guard lock(mutex_);
      busy_ = false;
      if (error && !error_) error_ = error;
      if (error_) has_queued_ = false;  // nothing after a failed frame is written
    }
    changed_.notify_all();
  }
}

}  // namespace treeanim
