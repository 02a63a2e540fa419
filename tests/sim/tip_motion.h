#pragma once
// A small tree's sway in a wind, for tests that compare trees or winds: header-only.
#include <Eigen/Core>
#include <vector>

#include "sim/simulator.h"
#include "sim/sim_test_models.h"

namespace treeanim::testing {

// The tip displacement from rest (m) of small_tree(6) standing at `origin`, every frame of `frames`.
inline std::vector<Eigen::Vector3d> tip_motion(const Eigen::Vector3d& origin, const WindOptions& wind, int frames) {
  const TreeModel model = small_tree(6, origin);
  Eigen::Index tip = 0;
  model.rest_positions.row(1).maxCoeff(&tip);
  Simulator sim(model, HsmOptions{}, wind, 1.0 / 24, 4);
  SimState state = sim.initial_state(0);
  std::vector<Eigen::Vector3d> motion;
  for (int f = 1; f <= frames; ++f) {
    sim.advance_frame(state, f);
    motion.push_back(state.positions.col(tip) - model.rest_positions.col(tip));
  }
  return motion;
}

}  // namespace treeanim::testing
