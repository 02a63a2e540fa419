#pragma once
// Stage entry point: TreeModel + options => frames of SimState.
#include <memory>

#include "sim/sim_options.h"
#include "sim/sim_state.h"
#include "tree/tree_model.h"

namespace treeanim {

class Simulator {
 public:
  // model: read-only tree (must outlive the simulator); frame_dt: 1/fps; substeps per frame.
  Simulator(const TreeModel& model, const HsmOptions& options, const WindOptions& wind,
            double frame_dt, int substeps);
  ~Simulator();
  Simulator(const Simulator&) = delete;
  Simulator& operator=(const Simulator&) = delete;

  // The tree at rest at `time` (equilibrium: it does not sag when the bake starts).
  SimState initial_state(double time) const;
  // Advances `state` by one frame (substeps steps). Throws SimulationError naming the frame,
  // substep and cluster when a value becomes non-finite; `state` is then unspecified.
  void advance_frame(SimState& state, long long frame);

  // The solver behind it, in the precision of options.precision (sim/simulator.cpp).
  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace treeanim
