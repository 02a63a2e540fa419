// One sweep per substep (docs/solver.md, "One sweep"): the clusters in order, each thread its
// share of them. In a cluster's turn the vertices in it alone are predicted (their goals from
// the chain's deflected pose), the cluster is fitted, and those vertices are corrected and
// load the next step while they are in cache. The other vertices (the overlap rings, the
// attached leaves) are predicted before the sweep and corrected after it. Every vertex runs
// the operations of the separate passes (match_clusters, correct_and_predict), so a bake has
// their bytes.
#include <omp.h>

#include <algorithm>
#include <string>

#include "common/errors.h"
#include "sim/kernel_isa.h"
#include "sim/shape_matching.h"
#include "sim/solver_step.h"
#include "sim/vertex_pass.h"

namespace treeanim {

namespace {

// What a sweep found wrong, each the lowest vertex or cluster (kNone: nothing).
struct SweepFaults {
  uint32_t prediction = kNone;  // a vertex predicted in this sweep
  uint32_t fit = kNone;         // a cluster
  uint32_t vertex = kNone;      // a corrected vertex
  uint32_t runaway = kNone;     // an attached vertex past the runaway limit (the last sweep of a frame)
  uint32_t next = kNone;        // a vertex of the next frame's first prediction

  void lower(const SweepFaults& o) {
    prediction = std::min(prediction, o.prediction), fit = std::min(fit, o.fit), vertex = std::min(vertex, o.vertex);
    runaway = std::min(runaway, o.runaway), next = std::min(next, o.next);
  }
  bool any() const { return prediction != kNone || fit != kNone || vertex != kNone || runaway != kNone; }
};

// A run of vertices => f(begin, n) on its blocks of at most kVertexBlock.
template <typename F>
inline void for_run_blocks(const VertexRun& run, F f) {
  for (size_t begin = run.begin; begin < run.end; begin += kVertexBlock)
    f(begin, static_cast<int>(std::min<size_t>(kVertexBlock, run.end - begin)));
}

// A block's goal rows: its own buffer (`own`), or the prediction's rows; `write`: written
// first from the chain's deflected poses.
template <typename Real>
inline GoalRows<Real> block_goals(const SolverModel<Real>& model, const Attachment<Real>& attachment,
                                  const StepScratch<Real>& scratch, StepPrediction<Real>& prediction,
                                  VertexBlock<Real>& block, size_t begin, int n, bool own, bool write) {
  const GoalRows<Real> goal =
      own ? GoalRows<Real>{block.goal[0], block.goal[1], block.goal[2], block.compliance, begin}
          : goal_rows(prediction, begin);
  if (write) write_static_offsets(model, attachment, scratch, goal, begin, begin + n);
  return goal;
}

// Vertices [begin, begin + n) => their prediction of this step from the corrected last one
// (the goals written first: into the block's buffer when `own`, else the prediction's rows).
template <typename Real>
void predict_vertices(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state,
                      const StepScratch<Real>& scratch, VertexBlock<Real>& block, size_t begin, int n, bool own,
                      SweepFaults& faults) {
  StepPrediction<Real>& prediction = state.prediction<Real>();
  const GoalRows<Real> goal = block_goals(model, attachment, scratch, prediction, block, begin, n, own, model.beam);
  const VertexInputs<Real> in = direct_inputs(model, attachment, scratch, begin, goal);
  uint32_t unused = kNone;
  if (predict_block<true>(model, attachment, scratch, prediction, begin, n, in, Real(1), block))
    locate_fault(model, attachment, prediction, begin, n, nullptr, false, faults.prediction, unused);
}

// Vertices [begin, begin + n), their clusters matched => corrected, and the next step's
// drag measured; `own`: their goals are written again into the block's buffer, as the
// prediction wrote them.
template <typename Real>
void correct_vertices(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state,
                      StepScratch<Real>& scratch, VertexBlock<Real>& block, size_t begin, int n, bool own, bool end,
                      SweepFaults& faults) {
  StepPrediction<Real>& prediction = state.prediction<Real>();
  const GoalRows<Real> goal = block_goals(model, attachment, scratch, prediction, block, begin, n, own, own);
  const VertexInputs<Real> in = direct_inputs(model, attachment, scratch, begin, goal);
  if (correct_any(model, attachment, scratch, prediction, begin, n, in, block, end))
    locate_fault(model, attachment, prediction, begin, n, nullptr, end, faults.vertex, faults.runaway);
}

}  // namespace

template <typename Real>
void sweep_clusters(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state,
                    StepScratch<Real>& scratch, bool predicted, bool end, long long frame, int substep) {
  // A vertex's goal in its own cluster's turn is kept in the block's buffer, not in memory.
  const bool own = model.beam && !predicted;
  SweepFaults faults;
#pragma omp parallel if (model.parallel)
  {
    SweepFaults mine;
    VertexBlock<Real> block;
    // 1. The other vertices' prediction (the first step of a frame finds it in the state).
    if (!predicted) {
#pragma omp for schedule(static)
      for (size_t r = 0; r < model.gathered_runs.size(); ++r)
        with_kernel_isa([&] {
          for_run_blocks(model.gathered_runs[r], [&](size_t begin, int n) {
            predict_vertices(model, attachment, state, scratch, block, begin, n, false, mine);
          });
        });
    }
    // 2. The sweep: a cluster's own vertices predicted, the cluster fitted (an attached leaf
    // after the branches, below), the air of its next step, its own vertices corrected.
    const std::pair<size_t, size_t> range =
        balanced_range(model.tree.cluster_offsets, omp_get_thread_num(), omp_get_num_threads());
    with_kernel_isa([&] {
      for (size_t c = range.first; c < range.second; ++c) {
        const VertexRun* runs = model.cluster_runs.data() + model.cluster_run_offsets[c];
        const size_t count = model.cluster_run_offsets[c + 1] - model.cluster_run_offsets[c];
        if (!predicted)
          for (size_t r = 0; r < count; ++r)
            for_run_blocks(runs[r], [&](size_t begin, int n) {
              predict_vertices(model, attachment, state, scratch, block, begin, n, own, mine);
            });
        if (attachment.cluster_pin_slot[c] == kNone && !match_cluster(model, attachment, state, scratch, c, nullptr))
          mine.fit = std::min(mine.fit, static_cast<uint32_t>(c));
        sample_cluster_air(model, attachment, state, scratch, c);
        for (size_t r = 0; r < count; ++r)
          for_run_blocks(runs[r], [&](size_t begin, int n) {
            correct_vertices(model, attachment, state, scratch, block, begin, n, own, end, mine);
          });
      }
    });
#pragma omp barrier
    if (!model.pinned_leaf_clusters.empty()) match_attached_leaves(model, attachment, state, scratch, mine.fit);
    // 3. The other vertices' correction, each the mean of its clusters' (a shared vertex's
    // mean into its pull row first, which the next prediction's kick reads).
#pragma omp for schedule(static)
    for (size_t r = 0; r < model.gathered_runs.size(); ++r)
      with_kernel_isa([&] {
        const VertexRun& run = model.gathered_runs[r];
        average_shared_pulls(model, attachment, scratch, run.begin, run.end);
        for_run_blocks(run, [&](size_t begin, int n) {
          correct_vertices(model, attachment, state, scratch, block, begin, n, false, end, mine);
        });
      });
#pragma omp critical(treeanim_sweep_faults)
    faults.lower(mine);
#pragma omp barrier
    // 4. The chain under the new loads; the last step of a frame writes the state and predicts
    // the next frame's first step.
    if (!faults.any()) {
      const std::pair<size_t, size_t> vertices =
          balanced_range(model.tree.vertex_cluster_offsets, omp_get_thread_num(), omp_get_num_threads());
      if (end) {
        const uint32_t next = deflect_and_predict(model, attachment, state, scratch, vertices.first, vertices.second,
                                                  false, VertexPass::kLastStep);
#pragma omp critical(treeanim_sweep_faults)
        faults.next = std::min(faults.next, next);
      } else if (model.beam) {
        deflect_bar_chain(model, attachment, state, scratch);
      }
    }
  }
  throw_vertex_fault(model, attachment, state, frame, substep, faults.prediction, kNone);
  if (faults.fit != kNone)
    throw SimulationError("frame " + std::to_string(frame) + ", substep " + std::to_string(substep) + ", cluster " +
                          std::to_string(faults.fit) + ": the shape match produced a non-finite rotation or centre");
  throw_vertex_fault(model, attachment, state, frame, substep, faults.vertex, faults.runaway);
  throw_vertex_fault(model, attachment, state, frame, substep, faults.next, kNone);
}

template void sweep_clusters(const SolverModel<float>&, const Attachment<float>&, SimState&, StepScratch<float>&,
                             bool, bool, long long, int);
template void sweep_clusters(const SolverModel<double>&, const Attachment<double>&, SimState&, StepScratch<double>&,
                             bool, bool, long long, int);

}  // namespace treeanim
