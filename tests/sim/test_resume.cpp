// SimState is complete: a state saved after any frame and loaded into a fresh Simulator
// continues with the same bits as the bake it came from, with leaves that detached before and
// after the save, with sleeping islands, at 1, 2 and 4 threads, in both precisions.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <vector>

#include "grown_tree.h"
#include "same_state.h"
#include "sim/simulator.h"
#include "sim/solver_model.h"

namespace treeanim {
namespace {

using testing::expect_same_state;
using testing::grown_tree;
using testing::same_bytes;

constexpr int kFrames = 72;
constexpr double kFrameDt = 1.0 / 24;
constexpr int kSubsteps = 3;

size_t detached_leaves(const SimState& state) {
  return static_cast<size_t>(std::count(state.leaf_attached.begin(), state.leaf_attached.end(), 0));
}

bool some_island_asleep(const SimState& state) {
  return std::any_of(state.island_asleep.begin(), state.island_asleep.end(), [](uint8_t a) { return a != 0; });
}

// Calm, rising to 20 m/s with 6 m/s gusts at 1 s, calm again from 1.1 s.
WindOptions rising_gale() {
  WindOptions wind;
  wind.keys = {{0, 0, {1, 0, 0.2}, 0}, {1.0, 20, {1, 0, 0.2}, 6}, {1.1, 0, {1, 0, 0.2}, 0}};
  return wind;
}

TEST(Resume, StateSavedAtAnyFrameContinuesBitIdenticallyInAFreshSimulator) {
  // Large enough to run in parallel; a rising gale that tears the leaves off over the first
  // second, then calm: the tree falls asleep (heavily damped, coarse thresholds, so within
  // the bake) while the leaves still fall.
  const TreeModel model = grown_tree(7, 2, 2);
  ASSERT_GE(model.membership_count(), kParallelMemberships);
  const WindOptions wind = rising_gale();
  const int saved_threads = omp_get_max_threads();
  for (Precision precision : {Precision::kDouble, Precision::kFloat}) {
    HsmOptions options;
    options.precision = precision;
    options.leaf_detach_force = 0.05;  // N: leaves let go between frames 7 and 17
    options.damping_ratio = 1;         // the tree settles and sleeps from frame ~47, leaves still falling
    options.sleep_velocity = 0.01;
    options.sleep_distance = 0.01;
    for (int threads : {1, 2, 4}) {
      SCOPED_TRACE(std::string(precision == Precision::kFloat ? "float" : "double") + ", " +
                   std::to_string(threads) + " threads");
      omp_set_num_threads(threads);
      Simulator whole(model, options, wind, kFrameDt, kSubsteps);
      std::vector<SimState> states{whole.initial_state(0)};
      for (int f = 1; f <= kFrames; ++f) {
        states.push_back(states.back());
        whole.advance_frame(states.back(), f);
      }
      // The bake covers the cases: leaves detach before and after a save; islands asleep
      // while leaves fly.
      bool detach_before_and_after = false, asleep_with_flying_leaf = false;
      for (int c = 1; c < kFrames; ++c) {
        detach_before_and_after |= detached_leaves(states[c]) > 0 && detached_leaves(states[c]) < detached_leaves(states[kFrames]);
        asleep_with_flying_leaf |= some_island_asleep(states[c]) && detached_leaves(states[c]) > 0;
      }
      EXPECT_TRUE(detach_before_and_after);
      EXPECT_TRUE(asleep_with_flying_leaf);
      // Saved before, during and after the detachments, around the tree falling asleep, asleep
      // (fewer with threads: on a loaded 2-core machine every parallel region costs ms).
      const std::vector<int> saves = threads == 1 ? std::vector<int>{0, 3, 10, 14, 28, 46, 47, 48, 49, 63, 70}
                                                  : std::vector<int>{10, 48, 63};
      for (int c : saves) {
        Simulator fresh(model, options, wind, kFrameDt, kSubsteps);
        SimState state = states[c];
        for (int f = c + 1; f <= kFrames; ++f) {
          fresh.advance_frame(state, f);
          ASSERT_TRUE(same_bytes(states[f].positions, state.positions)) << "saved at " << c << ", frame " << f;
        }
        expect_same_state(states[kFrames], state, kFrames);
      }
    }
  }
  omp_set_num_threads(saved_threads);
}

TEST(Resume, AnOlderStateFedBackToTheSameSimulatorContinuesAsFromAFreshOne) {
  // A simulator that detached leaves meets a state from before (leaves still attached): it
  // rebuilds its rest data from the state's flags instead of refusing.
  const TreeModel model = grown_tree(5, 2, 4);
  HsmOptions options;
  options.leaf_detach_force = 0.05;
  Simulator sim(model, options, rising_gale(), kFrameDt, kSubsteps);
  SimState early = sim.initial_state(0);
  for (int f = 1; f <= 10; ++f) sim.advance_frame(early, f);
  SimState late = early;
  for (int f = 11; f <= 30; ++f) sim.advance_frame(late, f);
  ASSERT_GT(detached_leaves(late), detached_leaves(early));
  SimState again = early;
  for (int f = 11; f <= 30; ++f) sim.advance_frame(again, f);
  expect_same_state(late, again, 30);
}

}  // namespace
}  // namespace treeanim
