#pragma once
// FrameThread: a written frame's mesh work on a thread of its own, behind the solver
// (docs/solver.md, "Particles"). While the solver's threads step frames k + 1 and k + 2 (one
// frame waits beside the one in hand), this thread handles frame k: the mesh placed from the
// samples' state (the skin), converted to floats, journalled and handed to the outputs. It
// works on a copy of what it reads of the state, so the solver goes on with its own; the same
// work on the same state gives the same bytes.
#include <functional>

#include "common/ordered_worker.h"
#include "sim/sim_state.h"

namespace treeanim {

class FrameThread {
 public:
  using Work = std::function<void(const SimState& state, long long frame)>;

  // Starts the thread. `work` runs there, one frame at a time in the order submitted, on one
  // OpenMP thread: the solver's team keeps the cores it was given. Destroyed, it drops a frame
  // not yet begun and lets the one in hand finish, without throwing.
  explicit FrameThread(Work work);

  // Queues frame `frame` of `state` (its positions, the velocities when `velocities`, the
  // clusters' rotations, the leaves' flags, the time), waiting while an earlier frame is queued.
  // Rethrows the first exception the work threw; no frame after that one is worked.
  void submit(const SimState& state, bool velocities, long long frame);
  // Returns once every frame submitted is done. Rethrows the first exception the work threw.
  void finish() { worker_.drain(); }

 private:
  struct Frame {
    SimState state;  // what the skin reads of it
    long long frame = 0;
  };
  OrderedWorker<Frame> worker_;
};

}  // namespace treeanim
