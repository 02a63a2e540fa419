#pragma once
// Stage entry point: TreeModel + options => frames of SimState.
#include <cstddef>
#include <memory>

#include "sim/sim_options.h"
#include "sim/sim_state.h"
#include "tree/tree_model.h"

namespace treeanim {

// Memberships per cache block of the step (docs/solver.md, "Cache blocks"): 16,384, or the
// environment's TREEANIM_BLOCKS (a count; 0: no blocks, the separate passes) for tests and
// benchmarks. Every value gives the same bytes. Read on the first call.
size_t cache_block_memberships();
// TREEANIM_BLOCKS set to anything but such a count => what is wrong with it; else "".
std::string asked_blocks_error();

class Simulator {
 public:
  // model: read-only tree (must outlive the simulator); frame_dt: 1/fps; substeps per frame;
  // block_memberships: see cache_block_memberships.
  Simulator(const TreeModel& model, const HsmOptions& options, const WindOptions& wind,
            double frame_dt, int substeps, size_t block_memberships = cache_block_memberships());
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
