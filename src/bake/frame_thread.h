#pragma once
// FrameThread: a written frame's mesh work on a thread of its own, one frame behind the
// solver (docs/solver.md, "The mesh"). While the solver's threads step frame k + 1, this thread
// handles frame k: the mesh placed from the samples' state (the skin), converted to floats,
// journalled and handed to the outputs. It works on a copy of what it reads of the state, so
// the solver goes on with its own; the same work on the same state gives the same bytes.
#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>

#include "sim/sim_state.h"

namespace treeanim {

class FrameThread {
 public:
  using Work = std::function<void(const SimState& state, long long frame)>;

  // Starts the thread. `work` runs there, one frame at a time in the order submitted, on one
  // OpenMP thread: the solver's team keeps the cores it was given.
  explicit FrameThread(Work work);
  // Drops a frame not yet begun, lets the one in hand finish, joins. Never throws: a bake
  // unwinding from an error has its own to report.
  ~FrameThread();
  FrameThread(const FrameThread&) = delete;
  FrameThread& operator=(const FrameThread&) = delete;

  // Queues frame `frame` of `state` (its positions, the velocities when `velocities`, the
  // clusters' rotations, the leaves' flags, the time), waiting while an earlier frame is queued.
  // Rethrows the first exception the work threw.
  void submit(const SimState& state, bool velocities, long long frame);
  // Returns once every frame submitted is done. Rethrows the first exception the work threw.
  void finish();

 private:
  void run();

  Work work_;
  std::mutex mutex_;
  std::condition_variable changed_;  // a frame queued or done, an error, or stopping
  // The frame waiting and the one being worked on: of a state, what the skin reads.
  SimState queued_, in_hand_;
  long long queued_frame_ = 0;
  bool has_queued_ = false, busy_ = false, stopping_ = false;
  std::exception_ptr error_;
  std::thread thread_;
};

}  // namespace treeanim
