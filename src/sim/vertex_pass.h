#pragma once
// What the per-vertex passes share (correction.cpp, cluster_sweep.cpp): the mean correction
// of a vertex, the state's write and the drive of the kernels of prediction.h over a thread's
// vertices in blocks.
#include <algorithm>
#include <utility>

#include "sim/prediction.h"
#include "sim/solver_step.h"

namespace treeanim {

// Vertex v => the mean of its clusters' corrections, summed in membership order (never the
// sum: Eq. 7 with overlaps). A released membership's row holds 0.
template <typename Real>
inline Eigen::Matrix<Real, 1, 3> mean_correction(const TreeModel& tree, const Attachment<Real>& attachment,
                                                 const StepScratch<Real>& scratch, uint32_t v) {
  Eigen::Matrix<Real, 1, 3> pull = Eigen::Matrix<Real, 1, 3>::Zero();
  for (uint32_t s = tree.vertex_cluster_offsets[v]; s < tree.vertex_cluster_offsets[v + 1]; ++s)
    pull += scratch.member_correction.row(tree.vertex_memberships[s]);
  return pull * attachment.vertex_inv_count[v];
}

// Shared vertices in [first, last) => their mean correction in their pull row, read by the
// direct vertex pass.
template <typename Real>
void average_shared_pulls(const SolverModel<Real>& model, const Attachment<Real>& attachment,
                          StepScratch<Real>& scratch, size_t first, size_t last) {
  const auto from = std::lower_bound(model.shared_vertices.begin(), model.shared_vertices.end(), first);
  const auto to = std::lower_bound(from, model.shared_vertices.end(), last);
  for (auto it = from; it != to; ++it)
    scratch.member_correction.row(attachment.vertex_pull_row[*it]) = mean_correction(model.tree, attachment, scratch, *it);
}

// Vertices [begin, begin + n) => block.moving (0: anchored, without an active cluster, or
// asleep), their factors and, `with_pull`, block.pull, each vertex's mean correction;
// kFromState first loads u = x - x0 and v from the state (anchors included: they hold where
// they are).
template <typename Real>
void gather_block(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state,
                  const StepScratch<Real>& scratch, bool load_state, bool with_pull, bool any_asleep, size_t begin,
                  int n, VertexBlock<Real>& block) {
  const TreeModel& tree = model.tree;
  StepPrediction<Real>& prediction = state.prediction<Real>();
  for (int k = 0; k < n; ++k) {
    const size_t v = begin + k;
    const bool still = tree.vertex_anchored[v] || attachment.vertex_inv_count[v] == 0 ||
                       (any_asleep && !attachment.vertex_flying[v] && state.island_asleep[model.vertex_island[v]]);
    block.moving[k] = still ? 0 : 1;
    block.drag[k] = still ? Real(0) : model.vertex_drag[v];
    block.half_damping[k] = still ? Real(1) : model.vertex_half_damping[v];
    block.global[k] = still ? Real(0) : attachment.vertex_global[v];
    block.flying[k] = still ? 0 : attachment.vertex_flying[v];
    Eigen::Matrix<Real, 3, 1> pull = Eigen::Matrix<Real, 3, 1>::Zero();
    if (load_state) {
      prediction.offset.row(v) = (state.positions.col(v) - tree.rest_positions.col(v)).transpose().template cast<Real>();
      prediction.velocity.row(v) = state.velocities.col(v).transpose().template cast<Real>();
    } else if (with_pull && !still) {
      pull = mean_correction(tree, attachment, scratch, static_cast<uint32_t>(v)).transpose();
    }
    for (int i = 0; i < 3; ++i) block.pull[i][k] = pull[i];
  }
}

// The corrected vertices [first, last) (prediction) => the state's positions and velocities,
// in double; a vertex that does not move keeps its values.
template <typename Real>
void write_state(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state,
                 bool any_asleep, size_t first, size_t last) {
  const TreeModel& tree = model.tree;
  const StepPrediction<Real>& prediction = state.prediction<Real>();
  for (size_t v = first; v < last; ++v) {
    const bool still = tree.vertex_anchored[v] || attachment.vertex_inv_count[v] == 0 ||
                       (any_asleep && !attachment.vertex_flying[v] && state.island_asleep[model.vertex_island[v]]);
    if (still) continue;
    state.positions.col(v) = tree.rest_positions.col(v) + prediction.offset.row(v).transpose().template cast<double>();
    state.velocities.col(v) = prediction.velocity.row(v).transpose().template cast<double>();
  }
}

// Vertices from `begin` => the kernels' inputs read straight from the model's and the
// attachment's arrays (no vertex asleep, none loaded from the state): each vertex's mean
// correction in its pull row, its goal and damping compliance at `goal` (indexed from begin).
template <typename Real>
inline VertexInputs<Real> direct_inputs(const SolverModel<Real>& model, const Attachment<Real>& attachment,
                                        const StepScratch<Real>& scratch, size_t begin, const GoalRows<Real>& goal) {
  const Rows3<Real>& corrections = scratch.member_correction;
  return {{corrections.col(0).data(), corrections.col(1).data(), corrections.col(2).data()},
          attachment.vertex_pull_row.data() + begin,
          model.vertex_drag.data() + begin,
          model.vertex_half_damping.data() + begin,
          attachment.vertex_global.data() + begin,
          attachment.vertex_flying.data() + begin,
          {goal.x, goal.y, goal.z},
          goal.compliance,
          model.vertex_shape_kick.data() + begin};
}

// A flagged block of n vertices from `begin` (moving: which step; null: all) => the lowest
// vertex whose values are not finite lowers `bad`, and (`check_runaway`) the lowest attached
// one farther than the runaway limit lowers `runaway`, as the scalar tests would find them.
template <typename Real>
void locate_fault(const SolverModel<Real>& model, const Attachment<Real>& attachment,
                  const StepPrediction<Real>& prediction, size_t begin, int n, const uint8_t* moving,
                  bool check_runaway, uint32_t& bad, uint32_t& runaway) {
  for (int k = 0; k < n; ++k) {
    if (moving && !moving[k]) continue;
    const uint32_t v = static_cast<uint32_t>(begin + k);
    if (!prediction.offset.row(v).allFinite() || !prediction.velocity.row(v).allFinite()) bad = std::min(bad, v);
    if (check_runaway && !attachment.vertex_flying[v] &&
        prediction.offset.row(v).template cast<double>().squaredNorm() > model.runaway_distance2)
      runaway = std::min(runaway, v);
  }
}

// correct_block for a pass: with the state's write (`end`), with the drag (the beam or
// detaching leaves) => whether the block is flagged.
template <typename Real>
inline bool correct_any(const SolverModel<Real>& model, const Attachment<Real>& attachment, StepScratch<Real>& scratch,
                        StepPrediction<Real>& prediction, size_t begin, int n, const VertexInputs<Real>& in,
                        VertexBlock<Real>& block, bool end) {
  if (model.store_drag_force)
    return end ? correct_block<true, true>(model, attachment, scratch, prediction, begin, n, in, block)
               : correct_block<false, true>(model, attachment, scratch, prediction, begin, n, in, block);
  return end ? correct_block<true, false>(model, attachment, scratch, prediction, begin, n, in, block)
             : correct_block<false, false>(model, attachment, scratch, prediction, begin, n, in, block);
}

// One kernel over this thread's vertices [first, last), in blocks => the lowest vertex whose
// values are not finite and (`check_runaway`) the lowest attached one farther than the
// runaway limit. `before` runs on each block's range first.
// Without sleeping islands every free vertex reads its mean correction from one row
// (anchors: the zero row, with factors that keep them still), which the first pass of a step
// averages (`first_pass`); otherwise, and when a frame starts from the state, each block is
// gathered lane by lane.
template <typename Real, typename Before, typename Kernel>
std::pair<uint32_t, uint32_t> for_vertex_blocks(const SolverModel<Real>& model, const Attachment<Real>& attachment,
                                                SimState& state, StepScratch<Real>& scratch, size_t first,
                                                size_t last, bool load_state, bool with_pull, bool first_pass,
                                                bool any_asleep, bool check_runaway, Before before, Kernel kernel) {
  StepPrediction<Real>& prediction = state.prediction<Real>();
  uint32_t bad = kNone, runaway = kNone;
  const bool direct = !load_state && !any_asleep;
  if (direct && with_pull && first_pass) average_shared_pulls(model, attachment, scratch, first, last);
  VertexBlock<Real> block;
  for (size_t begin = first; begin < last; begin += kVertexBlock) {
    const int n = static_cast<int>(std::min<size_t>(kVertexBlock, last - begin));
    before(begin, begin + n);
    const GoalRows<Real> goal = goal_rows(prediction, begin);
    VertexInputs<Real> in;
    if (direct) {
      in = direct_inputs(model, attachment, scratch, begin, goal);
      std::fill(block.moving, block.moving + n, uint8_t(1));
    } else {
      gather_block(model, attachment, state, scratch, load_state, with_pull, any_asleep, begin, n, block);
      in = {{block.pull[0], block.pull[1], block.pull[2]}, kLaneIndex.data(), block.drag, block.half_damping,
            block.global, block.flying, {goal.x, goal.y, goal.z}, goal.compliance,
            model.vertex_shape_kick.data() + begin};
    }
    if (kernel(begin, n, in, block)) locate_fault(model, attachment, prediction, begin, n, block.moving, check_runaway, bad, runaway);
  }
  return {bad, runaway};
}


}  // namespace treeanim
