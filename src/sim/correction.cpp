// The per-vertex pass, in displacements from rest (u = x - x0): the correction of the step
// just matched (Eq. 7: each vertex takes the mean of its clusters' corrections), fused with
// the prediction of the next step (prediction.h), so a vertex is loaded once per substep
// (docs/solver.md, "One step" 5, 1 and 3).
#include <omp.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cstdio>
#include <string>

#include "common/errors.h"
#include "sim/kernel_isa.h"
#include "sim/prediction.h"
#include "sim/solver_step.h"

namespace treeanim {

namespace {

// A vertex's n memberships, the k-th's correction in row row_of(k), and 1 / its active ones
// => the mean of its clusters' corrections, summed in membership order (never the sum: Eq. 7
// with overlaps). A released membership's row holds 0.
template <typename Real, typename RowOf>
inline Eigen::Matrix<Real, 1, 3> mean_correction(const StepScratch<Real>& scratch, uint32_t n, Real share,
                                                 RowOf row_of) {
  Eigen::Matrix<Real, 1, 3> pull = Eigen::Matrix<Real, 1, 3>::Zero();
  for (uint32_t k = 0; k < n; ++k) pull += scratch.member_correction.row(row_of(k));
  return pull * share;
}

// Shared vertices in [first, last) => their mean correction in their own row, read by the
// direct vertex pass. Their memberships' rows come from the model's own list, read in order.
template <typename Real>
void average_shared_pulls(const SolverModel<Real>& model, const Attachment<Real>& attachment,
                          StepScratch<Real>& scratch, size_t first, size_t last) {
  const std::vector<uint32_t>& shared = model.shared_vertices;
  const size_t from = std::lower_bound(shared.begin(), shared.end(), first) - shared.begin();
  const size_t to = std::lower_bound(shared.begin() + from, shared.end(), last) - shared.begin();
  const uint32_t* offsets = model.shared_row_offsets.data();
  for (size_t i = from; i < to; ++i) {
    const uint32_t v = shared[i];
    const uint32_t* rows = model.shared_correction_rows.data() + offsets[i];
    scratch.member_correction.row(v) = mean_correction(scratch, offsets[i + 1] - offsets[i],
                                                       attachment.vertex_inv_count[v],
                                                       [rows](uint32_t k) { return rows[k]; });
  }
}

// How a vertex pass reads and checks its blocks.
struct BlockPass {
  bool load_state = false;     // u = x - x0 and v loaded from the state first (kFromState)
  bool with_pull = false;      // each vertex takes its mean correction
  bool first_pass = false;     // the step's first pass: it averages the shared vertices' corrections
  bool any_asleep = false;     // islands asleep: their vertices stand still
  bool check_runaway = false;  // the attached vertices checked against the runaway limit
};

// Vertices [begin, begin + n) => block.moving (0: anchored, without an active cluster, or
// asleep), their factors and, `with_pull`, block.pull, each vertex's mean correction;
// `load_state` first loads u = x - x0 and v from the state (anchors included: they hold where
// they are).
template <typename Real>
void gather_block(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state,
                  const StepScratch<Real>& scratch, const BlockPass& pass, size_t begin, int n,
                  VertexBlock<Real>& block) {
  const TreeModel& tree = model.tree;
  StepPrediction<Real>& prediction = state.prediction<Real>();
  for (int k = 0; k < n; ++k) {
    const size_t v = begin + k;
    const bool still = tree.vertex_anchored[v] || attachment.vertex_inv_count[v] == 0 ||
                       (pass.any_asleep && !attachment.vertex_flying[v] &&
                        state.island_asleep[model.vertex_island[v]]);
    block.moving[k] = still ? 0 : 1;
    block.drag[k] = still ? Real(0) : model.vertex_drag[v];
    block.half_damping[k] = still ? Real(1) : attachment.vertex_half_damping[v];
    block.kick_scale[k] = still ? Real(1) : attachment.vertex_kick_scale[v];
    block.global[k] = still ? Real(0) : attachment.vertex_global[v];
    block.flying[k] = still ? Real(0) : Real(attachment.vertex_flying[v]);
    Eigen::Matrix<Real, 3, 1> pull = Eigen::Matrix<Real, 3, 1>::Zero();
    if (pass.load_state) {
      prediction.offset.row(v) = (state.positions.col(v) - tree.rest_positions.col(v)).transpose().template cast<Real>();
      prediction.velocity.row(v) = state.velocities.col(v).transpose().template cast<Real>();
    } else if (pass.with_pull && !still) {
      const uint32_t* slots = tree.vertex_memberships.data() + tree.vertex_cluster_offsets[v];
      pull = mean_correction(scratch, tree.vertex_cluster_offsets[v + 1] - tree.vertex_cluster_offsets[v],
                             attachment.vertex_inv_count[v],
                             [&](uint32_t k) { return model.member_correction_row[slots[k]]; })
                 .transpose();
    }
    for (int i = 0; i < 3; ++i) block.pull[i][k] = pull[i];
  }
}

// One kernel over this thread's vertices [first, last), in blocks => the lowest vertex whose
// values are not finite and (`pass.check_runaway`) the lowest attached one farther than the
// runaway limit. `before` runs on each block's range first.
// Without sleeping islands every vertex reads its mean correction from its own row (anchors:
// a zero row, with factors that keep them still), which the first pass of a step averages for
// the shared vertices (`first_pass`); otherwise, and when a frame starts from the state, each block is
// gathered lane by lane.
template <typename Real, typename Before, typename Kernel>
std::pair<uint32_t, uint32_t> for_vertex_blocks(const SolverModel<Real>& model, const Attachment<Real>& attachment,
                                                SimState& state, StepScratch<Real>& scratch, size_t first,
                                                size_t last, const BlockPass& pass, Before before, Kernel kernel) {
  StepPrediction<Real>& prediction = state.prediction<Real>();
  uint32_t bad = kNone, runaway = kNone;
  const bool direct = !pass.load_state && !pass.any_asleep;
  if (direct && pass.with_pull && pass.first_pass) average_shared_pulls(model, attachment, scratch, first, last);
  const Real* corrections[3] = {scratch.member_correction.col(0).data(), scratch.member_correction.col(1).data(),
                                scratch.member_correction.col(2).data()};
  VertexBlock<Real> block;
  for (size_t begin = first; begin < last; begin += kVertexBlock) {
    const int n = static_cast<int>(std::min<size_t>(kVertexBlock, last - begin));
    before(begin, begin + n);
    VertexInputs<Real> in;
    if (direct) {
      in = {{corrections[0] + begin, corrections[1] + begin, corrections[2] + begin},
            model.vertex_drag.data() + begin, attachment.vertex_half_damping.data() + begin,
            attachment.vertex_kick_scale.data() + begin, attachment.vertex_global.data() + begin, block.flying, {}, nullptr};
      std::fill(block.moving, block.moving + n, uint8_t(1));
      std::copy_n(attachment.vertex_flying.data() + begin, n, block.flying);
    } else {
      gather_block(model, attachment, state, scratch, pass, begin, n, block);
      in = {{block.pull[0], block.pull[1], block.pull[2]}, block.drag, block.half_damping,
            block.kick_scale, block.global, block.flying, {}, nullptr};
    }
    for (int i = 0; i < 3; ++i) in.goal[i] = prediction.goal.col(i).data() + begin;
    std::copy_n(model.vertex_shape_kick.data() + begin, n, block.kicked);
    in.kicked = block.kicked;
    if (!kernel(begin, n, in, block)) continue;
    // Rare: find the first vertex at fault, as the scalar tests would.
    for (int k = 0; k < n; ++k) {
      if (!block.moving[k]) continue;
      const uint32_t v = static_cast<uint32_t>(begin + k);
      if (!prediction.offset.row(v).allFinite() || !prediction.velocity.row(v).allFinite()) bad = std::min(bad, v);
      if (pass.check_runaway && !attachment.vertex_flying[v] &&
          prediction.offset.row(v).template cast<double>().squaredNorm() > model.runaway_distance2)
        runaway = std::min(runaway, v);
    }
  }
  return {bad, runaway};
}

}  // namespace

template <typename Real>
std::pair<uint32_t, uint32_t> correct_vertices(const SolverModel<Real>& model, const Attachment<Real>& attachment,
                                               SimState& state, StepScratch<Real>& scratch, VertexPassMode mode,
                                               size_t first, size_t last) {
  StepPrediction<Real>& prediction = state.prediction<Real>();
  auto nothing = [](size_t, size_t) {};
  const BlockPass pass = {.load_state = mode.from_state,
                          .with_pull = !mode.from_state,
                          .first_pass = true,
                          .any_asleep = mode.any_asleep,
                          .check_runaway = mode.last};
  return with_kernel_isa([&] {
    return for_vertex_blocks(
        model, attachment, state, scratch, first, last, pass, nothing,
        [&](size_t begin, int n, const VertexInputs<Real>& in, VertexBlock<Real>& block) {
          if (model.store_drag_force)
            return mode.last ? correct_block<true, true>(model, attachment, scratch, prediction, begin, n, in, block)
                             : correct_block<false, true>(model, attachment, scratch, prediction, begin, n, in, block);
          return mode.last ? correct_block<true, false>(model, attachment, scratch, prediction, begin, n, in, block)
                           : correct_block<false, false>(model, attachment, scratch, prediction, begin, n, in, block);
        });
  });
}

template <typename Real>
uint32_t predict_vertices(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state,
                          StepScratch<Real>& scratch, VertexPassMode mode, size_t first, size_t last) {
  StepPrediction<Real>& prediction = state.prediction<Real>();
  // The state's velocities are taken at its time: the first kick from them is half a step's.
  const Real kick = mode.from_state ? Real(0.5) : Real(1);
  auto goals = [&](size_t begin, size_t stop) {
    if (model.beam) write_static_offsets(model, attachment, scratch, prediction, begin, stop);
  };
  const BlockPass pass = {.with_pull = !mode.from_state, .any_asleep = mode.any_asleep};
  return with_kernel_isa([&] {
    return for_vertex_blocks(model, attachment, state, scratch, first, last, pass, goals,
                             [&](size_t begin, int n, const VertexInputs<Real>& in, VertexBlock<Real>& block) {
                               const bool drags = !model.beam || std::any_of(in.flying, in.flying + n,
                                                                              [](Real f) { return f != 0; });
                               if (drags)
                                 return mode.last ? predict_block<false, true>(model, attachment, scratch, prediction,
                                                                               begin, n, in, kick, block)
                                                  : predict_block<true, true>(model, attachment, scratch, prediction,
                                                                              begin, n, in, kick, block);
                               return mode.last ? predict_block<false, false>(model, attachment, scratch, prediction,
                                                                              begin, n, in, kick, block)
                                                : predict_block<true, false>(model, attachment, scratch, prediction,
                                                                             begin, n, in, kick, block);
                             });
  }).first;
}

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

template <typename Real>
void throw_vertex_failure(const SolverModel<Real>& model, const Attachment<Real>& attachment, const SimState& state,
                          long long frame, int substep, uint32_t bad, uint32_t runaway) {
  // Particle v => "frame F, substep S, cluster C (vertex v): " for the messages below; in
  // "samples" v is no mesh vertex, so it is named for what it is.
  const char* particle = model.options.particles == ParticleMode::kSamples ? " (hsm.particles sample " : " (vertex ";
  auto where = [&](uint32_t v) {
    return "frame " + std::to_string(frame) + ", substep " + std::to_string(substep) + ", cluster " +
           std::to_string(attachment.vertex_air_cluster[v]) + particle + std::to_string(v) + "): ";
  };
  if (bad != kNone) throw SimulationError(where(bad) + "non-finite position or velocity");
  if (runaway == kNone) return;
  const StepPrediction<Real>& prediction = state.prediction<Real>();
  char distances[160];
  std::snprintf(distances, sizeof distances, "moved %.3g m from rest, more than %.3g times the tree's size (%.3g m, its reach along the branches or its extent)",
                prediction.offset.row(runaway).template cast<double>().norm(), kRunawaySizes,
                std::sqrt(model.runaway_distance2) / kRunawaySizes);
  // Without the global term nothing holds a limb's bending but its clusters' overlaps: no
  // step or local stiffness keeps a tree standing in a wind that tears those apart.
  throw SimulationError(where(runaway) + distances +
                        (model.beam ? ": the tree came apart; raise time.substeps or the stiffness"
                                    : ": the tree came apart: without the global term (hsm.global_matching false) only "
                                      "its clusters' local shapes hold it, which this wind overcomes; turn the global "
                                      "term on") +
                        " (docs/solver.md, \"Runaway\")");
}

// One parallel region: the correction (and load) pass; after a barrier, the state (kLastStep)
// and the bar chain's passes; the prediction, each block's goals first. A failure found by a
// pass stops every thread after it; the exceptions are thrown outside the region.
template <typename Real>
bool correct_and_predict(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state,
                         StepScratch<Real>& scratch, VertexPass pass, long long frame, int substep) {
  const bool any_asleep = std::any_of(state.island_asleep.begin(), state.island_asleep.end(),
                                      [](uint8_t a) { return a != 0; });
  const VertexPassMode mode = {.from_state = pass == VertexPass::kFromState,
                               .last = pass == VertexPass::kLastStep,
                               .any_asleep = any_asleep};
  uint32_t bad = kNone, runaway = kNone, bad_prediction = kNone;
#pragma omp parallel if (model.parallel)
  {
    const auto [first, last] =
        balanced_range(model.tree.vertex_cluster_offsets, omp_get_thread_num(), omp_get_num_threads());
    // 5. Correct the matched step (or load the state), and 1. measure the drag of the next one.
    const auto [my_bad, my_runaway] = correct_vertices(model, attachment, state, scratch, mode, first, last);
    if (my_bad != kNone || my_runaway != kNone) {
#pragma omp critical(treeanim_correction_failure)
      bad = std::min(bad, my_bad), runaway = std::min(runaway, my_runaway);
    }
#pragma omp barrier
    if (bad == kNone && runaway == kNone) {
      if (mode.last) write_state(model, attachment, state, any_asleep, first, last);
      // 2. The static deflection under that drag, and 3. the prediction of the next step.
      if (model.beam) deflect_bar_chain(model, attachment, state, scratch);
      const uint32_t my_bad_prediction = predict_vertices(model, attachment, state, scratch, mode, first, last);
      if (my_bad_prediction != kNone) {
#pragma omp critical(treeanim_correction_failure)
        bad_prediction = std::min(bad_prediction, my_bad_prediction);
      }
    }
  }
  throw_vertex_failure(model, attachment, state, frame, substep, bad, runaway);
  throw_vertex_failure(model, attachment, state, frame, substep, bad_prediction, kNone);
  return any_asleep;
}

template <typename Real>
void predict_from_state(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state,
                        StepScratch<Real>& scratch, long long frame) {
  set_air_time(model, state.time, scratch);
  scratch.member_correction.setZero();  // no step was matched: no shape kick (a rare pass)
#pragma omp parallel for schedule(static) if (model.parallel)
  for (size_t c = 0; c < model.C; ++c) {
    // The clusters' rotations as the last match left them (the drag's rest frame, prediction.h).
    Eigen::Map<Eigen::Matrix3d>(&scratch.cluster_rotation_matrix(0, c)) =
        Eigen::Quaterniond(state.cluster_rotations.col(c)).toRotationMatrix();
    if (cluster_awake(model, attachment, state, c)) sample_cluster_air(model, attachment, state, scratch, c);
  }
  correct_and_predict(model, attachment, state, scratch, VertexPass::kFromState, frame, 0);
}

template bool correct_and_predict(const SolverModel<float>&, const Attachment<float>&, SimState&, StepScratch<float>&,
                                  VertexPass, long long, int);
template bool correct_and_predict(const SolverModel<double>&, const Attachment<double>&, SimState&,
                                  StepScratch<double>&, VertexPass, long long, int);
template void predict_from_state(const SolverModel<float>&, const Attachment<float>&, SimState&, StepScratch<float>&,
                                 long long);
template void predict_from_state(const SolverModel<double>&, const Attachment<double>&, SimState&,
                                 StepScratch<double>&, long long);
#define TREEANIM_VERTEX_PASSES(Real)                                                                             \
  template std::pair<uint32_t, uint32_t> correct_vertices(const SolverModel<Real>&, const Attachment<Real>&,    \
                                                          SimState&, StepScratch<Real>&, VertexPassMode, size_t, \
                                                          size_t);                                               \
  template uint32_t predict_vertices(const SolverModel<Real>&, const Attachment<Real>&, SimState&,              \
                                     StepScratch<Real>&, VertexPassMode, size_t, size_t);                       \
  template void write_state(const SolverModel<Real>&, const Attachment<Real>&, SimState&, bool, size_t, size_t); \
  template void throw_vertex_failure(const SolverModel<Real>&, const Attachment<Real>&, const SimState&,         \
                                     long long, int, uint32_t, uint32_t);
TREEANIM_VERTEX_PASSES(float)
TREEANIM_VERTEX_PASSES(double)
#undef TREEANIM_VERTEX_PASSES

}  // namespace treeanim
