#pragma once
// Bit-exact comparisons of solver states, for tests that expect two ways of baking to agree.
#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "sim/sim_state.h"

namespace treeanim::testing {

// Bytes of an Eigen array or a vector, for bit-exact comparisons (NaN-safe, -0 != +0).
template <typename T>
bool same_bytes(const T& a, const T& b) {
  // An empty array may have no storage: memcmp takes no null pointer, even for no bytes.
  return a.size() == b.size() && (a.size() == 0 || std::memcmp(a.data(), b.data(), sizeof(*a.data()) * a.size()) == 0);
}

// Everything a bake hands out or carries on, bit for bit.
inline void expect_same_state(const SimState& expected, const SimState& actual, int frame) {
  SCOPED_TRACE("frame " + std::to_string(frame));
  EXPECT_TRUE(same_bytes(expected.positions, actual.positions));
  EXPECT_TRUE(same_bytes(expected.velocities, actual.velocities));
  EXPECT_TRUE(same_bytes(expected.cluster_rotations, actual.cluster_rotations));
  EXPECT_TRUE(same_bytes(expected.cluster_shift, actual.cluster_shift));
  EXPECT_EQ(expected.leaf_attached, actual.leaf_attached);
  EXPECT_EQ(expected.island_asleep, actual.island_asleep);
  EXPECT_EQ(expected.time, actual.time);
  EXPECT_EQ(expected.predicted, actual.predicted);
}

}  // namespace treeanim::testing
