// The frame thread (bake/frame_thread.h): every frame in order, on a copy of the state. Its
// queue, its errors and its end are OrderedWorker's (tests/common/test_ordered_worker.cpp).
#include "bake/frame_thread.h"

#include <gtest/gtest.h>

#include <vector>

namespace treeanim {
namespace {

SimState state_of(double value) {
  SimState state;
  state.positions = Eigen::Matrix3Xd::Constant(3, 5, value);
  state.velocities = Eigen::Matrix3Xd::Constant(3, 5, -value);
  state.cluster_rotations = Eigen::Matrix4Xd::Constant(4, 2, value);
  state.leaf_attached = {1, 0};
  state.time = value;
  return state;
}

struct Seen {
  long long frame;
  double position, velocity_columns, time;
};

TEST(FrameThread, WorksEveryFrameInOrderOnACopyOfItsState) {
  std::vector<Seen> seen;  // written by the thread alone until finish()
  FrameThread thread([&](const SimState& state, long long frame) {
    seen.push_back({frame, state.positions(2, 4), double(state.velocities.cols()), state.time});
  });
  SimState state;
  for (long long frame = 10; frame < 30; ++frame) {
    state = state_of(double(frame));
    thread.submit(state, frame % 2 == 0, frame);
    state.positions.setConstant(-1);  // the solver goes on with its own state
  }
  thread.finish();
  ASSERT_EQ(seen.size(), 20u);
  for (size_t k = 0; k < seen.size(); ++k) {
    const long long frame = 10 + static_cast<long long>(k);
    EXPECT_EQ(seen[k].frame, frame);
    EXPECT_EQ(seen[k].position, double(frame));
    EXPECT_EQ(seen[k].time, double(frame));
    EXPECT_EQ(seen[k].velocity_columns, frame % 2 == 0 ? 5.0 : 0.0);  // velocities only when asked
  }
}

}  // namespace
}  // namespace treeanim
