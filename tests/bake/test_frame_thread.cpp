// The frame thread (bake/frame_thread.h): every frame in order, on a copy of the state, and
// the work's first error given back to the solver's side.
#include "bake/frame_thread.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include "common/errors.h"

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

TEST(FrameThread, GivesBackTheFirstErrorAndWorksNoFrameAfterIt) {
  std::vector<long long> worked;
  FrameThread thread([&](const SimState&, long long frame) {
    worked.push_back(frame);
    if (frame == 3) throw OutputError("disk full at frame 3");
  });
  const SimState state = state_of(1);
  bool thrown = false;
  try {
    for (long long frame = 1; frame <= 10; ++frame) thread.submit(state, false, frame);
    thread.finish();
  } catch (const OutputError& e) {
    thrown = true;
    EXPECT_STREQ(e.what(), "disk full at frame 3");
  }
  EXPECT_TRUE(thrown);
  EXPECT_THROW(thread.finish(), OutputError);
  EXPECT_THROW(thread.submit(state, false, 11), OutputError);
  ASSERT_GE(worked.size(), 3u);
  EXPECT_EQ(worked.back(), 3);  // frames queued behind the failed one are dropped
}

TEST(FrameThread, EndsTheFrameInHandWhenDestroyed) {
  std::atomic<int> worked = 0;
  {
    FrameThread thread([&](const SimState&, long long) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      ++worked;
    });
    const SimState state = state_of(1);
    thread.submit(state, false, 1);
    thread.submit(state, false, 2);  // returns once frame 1 is in the thread's hands
  }  // as a bake unwinding from an error: frame 1 ends, frame 2 may be dropped
  EXPECT_GE(worked, 1);
  EXPECT_LE(worked, 2);
}

}  // namespace
}  // namespace treeanim
