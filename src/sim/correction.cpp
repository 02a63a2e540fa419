// The per-vertex pass, in displacements from rest (u = x - x0): the correction of the step
// just matched (Eq. 7: each vertex takes the mean of its clusters' corrections), fused with
// the prediction of the next step (prediction.h), so a vertex is loaded once per substep
// (docs/solver.md, "One step" 4 and 1).
#include <omp.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cstdio>
#include <string>

#include "common/errors.h"
#include "sim/kernel_isa.h"
#include "sim/solver_step.h"
#include "sim/vertex_pass.h"

namespace treeanim {


template <typename Real>
uint32_t deflect_and_predict(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state,
                             StepScratch<Real>& scratch, size_t first, size_t last, bool any_asleep,
                             VertexPass pass) {
  StepPrediction<Real>& prediction = state.prediction<Real>();
  const bool load = pass == VertexPass::kFromState, end = pass == VertexPass::kLastStep;
  // The state's velocities are taken at its time: the first kick from them is half a step's.
  const Real kick = load ? Real(0.5) : Real(1);
  if (end) write_state(model, attachment, state, any_asleep, first, last);
  // 1. The static deflection under that drag, and the prediction of the next step.
  if (model.beam) deflect_bar_chain(model, attachment, state, scratch);
  auto goals = [&](size_t begin, size_t stop) {
    if (model.beam) write_static_offsets(model, attachment, scratch, goal_rows(prediction, 0), begin, stop);
  };
  return with_kernel_isa([&] {
    return for_vertex_blocks(model, attachment, state, scratch, first, last, false, !load, false, any_asleep, false,
                             goals, [&](size_t begin, int n, const VertexInputs<Real>& in, VertexBlock<Real>& block) {
                               return end ? predict_block<false>(model, attachment, scratch, prediction, begin, n,
                                                                 in, kick, block)
                                          : predict_block<true>(model, attachment, scratch, prediction, begin, n,
                                                                in, kick, block);
                             });
  }).first;
}

template <typename Real>
void throw_vertex_fault(const SolverModel<Real>& model, const Attachment<Real>& attachment, const SimState& state,
                        long long frame, int substep, uint32_t bad, uint32_t runaway) {
  // Vertex v => "frame F, substep S, cluster C (vertex v): " for the messages below.
  auto where = [&](uint32_t v) {
    return "frame " + std::to_string(frame) + ", substep " + std::to_string(substep) + ", cluster " +
           std::to_string(attachment.vertex_air_cluster[v]) + " (vertex " + std::to_string(v) + "): ";
  };
  if (bad != kNone) throw SimulationError(where(bad) + "non-finite position or velocity");
  if (runaway != kNone) {
    char distances[160];
    std::snprintf(distances, sizeof distances, "moved %.3g m from rest, more than %.3g times the tree's size (%.3g m, its reach along the branches or its extent)",
                  state.prediction<Real>().offset.row(runaway).template cast<double>().norm(), kRunawaySizes,
                  std::sqrt(model.runaway_distance2) / kRunawaySizes);
    throw SimulationError(where(runaway) + distances +
                          ": the tree came apart; raise time.substeps or the stiffness (docs/solver.md, \"Runaway\")");
  }
}

// One parallel region: the correction (and load) pass; after a barrier, the state (kLastStep)
// and the bar chain's passes; the prediction, each block's goals first. A failure found by a
// pass stops every thread after it; the exceptions are thrown outside the region.
template <typename Real>
bool correct_and_predict(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state,
                         StepScratch<Real>& scratch, VertexPass pass, long long frame, int substep) {
  StepPrediction<Real>& prediction = state.prediction<Real>();
  const bool any_asleep = std::any_of(state.island_asleep.begin(), state.island_asleep.end(),
                                      [](uint8_t a) { return a != 0; });
  const bool load = pass == VertexPass::kFromState, end = pass == VertexPass::kLastStep;
  uint32_t bad = kNone, runaway = kNone, bad_prediction = kNone;
  auto nothing = [](size_t, size_t) {};
#pragma omp parallel if (model.parallel)
  {
    // Named, not a structured binding: the lambdas below capture them (clang before 16 cannot).
    const std::pair<size_t, size_t> range =
        balanced_range(model.tree.vertex_cluster_offsets, omp_get_thread_num(), omp_get_num_threads());
    const size_t first = range.first, last = range.second;
    // 4. Correct the matched step (or load the state), and measure the drag of the next one.
    const auto [my_bad, my_runaway] = with_kernel_isa([&] {
      return for_vertex_blocks(
          model, attachment, state, scratch, first, last, load, !load, true, any_asleep, end, nothing,
          [&](size_t begin, int n, const VertexInputs<Real>& in, VertexBlock<Real>& block) {
            return correct_any(model, attachment, scratch, prediction, begin, n, in, block, end);
          });
    });
    if (my_bad != kNone || my_runaway != kNone) {
#pragma omp critical(treeanim_correction_failure)
      bad = std::min(bad, my_bad), runaway = std::min(runaway, my_runaway);
    }
#pragma omp barrier
    if (bad == kNone && runaway == kNone) {
      const uint32_t my_bad_prediction =
          deflect_and_predict(model, attachment, state, scratch, first, last, any_asleep, pass);
      if (my_bad_prediction != kNone) {
#pragma omp critical(treeanim_correction_failure)
        bad_prediction = std::min(bad_prediction, my_bad_prediction);
      }
    }
  }
  throw_vertex_fault(model, attachment, state, frame, substep, bad, runaway);
  throw_vertex_fault(model, attachment, state, frame, substep, bad_prediction, kNone);
  return any_asleep;
}

template <typename Real>
void predict_from_state(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state,
                        StepScratch<Real>& scratch, long long frame) {
  set_air_time(model.wind, state.time, model.h, scratch.air);
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
template uint32_t deflect_and_predict(const SolverModel<float>&, const Attachment<float>&, SimState&,
                                      StepScratch<float>&, size_t, size_t, bool, VertexPass);
template uint32_t deflect_and_predict(const SolverModel<double>&, const Attachment<double>&, SimState&,
                                      StepScratch<double>&, size_t, size_t, bool, VertexPass);
template void throw_vertex_fault(const SolverModel<float>&, const Attachment<float>&, const SimState&, long long,
                                 int, uint32_t, uint32_t);
template void throw_vertex_fault(const SolverModel<double>&, const Attachment<double>&, const SimState&, long long,
                                 int, uint32_t, uint32_t);
template void predict_from_state(const SolverModel<float>&, const Attachment<float>&, SimState&, StepScratch<float>&,
                                 long long);
template void predict_from_state(const SolverModel<double>&, const Attachment<double>&, SimState&,
                                 StepScratch<double>&, long long);

}  // namespace treeanim
