// One step in cache blocks (docs/solver.md, "Cache blocks"): each block of clusters is
// predicted, matched, corrected and its loads summed in turn, so that its vertices come from
// memory once a step and the passes after the first find them in the cache. Every value is
// computed by the passes of match_clusters and correct_and_predict, with the same operations
// in the same order: a block only changes when each is computed, so the bytes are the same.
#include <omp.h>

#include <algorithm>

#include "sim/solver_step.h"

namespace treeanim {

namespace {

// The lowest vertex or cluster at fault in each pass of a step, kNone for none.
struct StepFailures {
  uint32_t prediction = kNone;       // vertex: the step's prediction
  uint32_t cluster = kNone;          // cluster: its fit
  uint32_t vertex = kNone;           // vertex: its correction
  uint32_t runaway = kNone;          // vertex: ran away (a frame's last step)
  uint32_t next_prediction = kNone;  // vertex: the prediction of the next frame's first step

  void lower_to(const StepFailures& other) {
    prediction = std::min(prediction, other.prediction);
    cluster = std::min(cluster, other.cluster);
    vertex = std::min(vertex, other.vertex);
    runaway = std::min(runaway, other.runaway);
    next_prediction = std::min(next_prediction, other.next_prediction);
  }
  bool any() const { return std::min({prediction, cluster, vertex, runaway, next_prediction}) != kNone; }
};

}  // namespace

template <typename Real>
bool step_in_blocks(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state,
                    StepScratch<Real>& scratch, BlockStep step, long long frame, int substep) {
  const bool any_asleep = std::any_of(state.island_asleep.begin(), state.island_asleep.end(),
                                      [](uint8_t a) { return a != 0; });
  // This step's prediction follows a step that was not a frame's last (which would have
  // predicted it); this step's own passes may be the last.
  const VertexPassMode previous = {.any_asleep = any_asleep}, mode = {.last = step.last, .any_asleep = any_asleep};
  const size_t blocks = model.block_cluster_offsets.size() - 1;
  const std::vector<uint32_t>& segment_offsets = model.block_segment_offsets;
  const std::vector<VertexSegment>& segments = model.block_segments;
  const std::span<const uint32_t> block_clusters(model.block_clusters), load_clusters(model.block_load_clusters);
  StepFailures failures;
#pragma omp parallel if (model.parallel)
  {
    StepFailures mine;
    auto predict_segment = [&](uint32_t i) {
      mine.prediction = std::min(mine.prediction, predict_vertices(model, attachment, state, scratch, previous,
                                                                   segments[i].begin, segments[i].end));
    };
    auto correct_segment = [&](uint32_t i) {
      const auto [bad, runaway] =
          correct_vertices(model, attachment, state, scratch, mode, segments[i].begin, segments[i].end);
      mine.vertex = std::min(mine.vertex, bad);
      mine.runaway = std::min(mine.runaway, runaway);
    };
    // 1. The border's vertices, before any block matches them.
    if (step.predict) {
#pragma omp for schedule(static)
      for (uint32_t i = segment_offsets[blocks]; i < segment_offsets[blocks + 1]; ++i) predict_segment(i);
    }
    // 2. This thread's blocks: each block's vertices predicted, its clusters matched (branches,
    // then the leaves pinned to them) with the next step's air, its vertices corrected and the
    // loads of its clusters without a border vertex summed.
    const auto [first, stop] = balanced_range(model.block_membership_offsets, omp_get_thread_num(), omp_get_num_threads());
    for (size_t b = first; b < stop; ++b) {
      if (step.predict)
        for (uint32_t i = segment_offsets[b]; i < segment_offsets[b + 1]; ++i) predict_segment(i);
      const uint32_t clusters_begin = model.block_cluster_offsets[b], clusters_end = model.block_cluster_offsets[b + 1];
      mine.cluster = std::min(mine.cluster, match_listed_clusters(model, attachment, state, scratch,
                                                                  block_clusters.subspan(clusters_begin,
                                                                                         clusters_end - clusters_begin)));
      for (uint32_t i = segment_offsets[b]; i < segment_offsets[b + 1]; ++i) correct_segment(i);
      if (model.beam)
        sum_cluster_loads(model, attachment, state, scratch,
                          load_clusters.subspan(model.block_load_offsets[b],
                                                model.block_load_offsets[b + 1] - model.block_load_offsets[b]));
    }
#pragma omp barrier
    // 3. The border once every block is matched, then the loads of the clusters it belongs to.
#pragma omp for schedule(static)
    for (uint32_t i = segment_offsets[blocks]; i < segment_offsets[blocks + 1]; ++i) correct_segment(i);
    if (model.beam) {
#pragma omp for schedule(static)
      for (uint32_t i = model.block_load_offsets[blocks]; i < model.block_load_offsets[blocks + 1]; ++i)
        sum_cluster_loads(model, attachment, state, scratch, load_clusters.subspan(i, 1));
    }
#pragma omp critical(treeanim_block_failure)
    failures.lower_to(mine);
#pragma omp barrier
    // 4. The chain, as correct_and_predict walks it; a frame's last step writes the state and
    // predicts the next frame's first.
    if (!failures.any()) {
      const auto [vertex_first, vertex_stop] =
          balanced_range(model.tree.vertex_cluster_offsets, omp_get_thread_num(), omp_get_num_threads());
      if (step.last) write_state(model, attachment, state, any_asleep, vertex_first, vertex_stop);
      if (model.beam) walk_bar_chain(model, attachment, scratch);
      if (step.last) {
        const uint32_t bad = predict_vertices(model, attachment, state, scratch, mode, vertex_first, vertex_stop);
        if (bad != kNone) {
#pragma omp critical(treeanim_block_failure)
          failures.next_prediction = std::min(failures.next_prediction, bad);
        }
      }
    }
  }
  // In the order, and with the substep, of the separate passes: this step's prediction was
  // theirs of the step before.
  throw_vertex_failure(model, attachment, state, frame, substep - 1, failures.prediction, kNone);
  if (failures.cluster != kNone) throw_match_failure(frame, substep, failures.cluster);
  throw_vertex_failure(model, attachment, state, frame, substep, failures.vertex, failures.runaway);
  throw_vertex_failure(model, attachment, state, frame, substep, failures.next_prediction, kNone);
  return any_asleep;
}

template bool step_in_blocks(const SolverModel<float>&, const Attachment<float>&, SimState&, StepScratch<float>&,
                             BlockStep, long long, int);
template bool step_in_blocks(const SolverModel<double>&, const Attachment<double>&, SimState&, StepScratch<double>&,
                             BlockStep, long long, int);

}  // namespace treeanim
