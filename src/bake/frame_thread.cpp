#include "bake/frame_thread.h"

#include <omp.h>

#include <utility>

namespace treeanim {

// One frame waits while another is in hand: the solver steps at most two frames ahead.
FrameThread::FrameThread(Work work)
    : worker_(1, [] { omp_set_num_threads(1); },
              [work = std::move(work)](Frame& frame) { work(frame.state, frame.frame); }) {}

void FrameThread::submit(const SimState& state, bool velocities, long long frame) {
  Frame copy;
  copy.state.positions = state.positions;
  if (velocities) copy.state.velocities = state.velocities;
  else copy.state.velocities.resize(3, 0);
  copy.state.cluster_rotations = state.cluster_rotations;
  copy.state.leaf_attached = state.leaf_attached;
  copy.state.time = state.time;
  copy.frame = frame;
  worker_.push(std::move(copy));
}

}  // namespace treeanim
