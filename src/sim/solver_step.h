#pragma once
// The phases of one frame (docs/solver.md, "One step"), free functions over the solver's
// model, the attachment it derives from the state, the state and the step's scratch. Each is
// defined in the file named after what it computes and instantiated for float and double.
#include <cstdint>

#include "sim/solver_model.h"

namespace treeanim {

// --- air.cpp ---
// t, step h => the wind terms every cluster shares at t (mean, gust, turbulence amplitude,
// phases), each wave averaged over the step (WindField::sample_time).
void set_air_time(const WindField& wind, double t, double step, AirSample& air);
// Cluster c + air at a time => scratch.cluster_air row c: at its rest centre, or for a
// flying leaf at the centre of its last fit (t0 + state.cluster_shift).
template <typename Real>
void sample_cluster_air(const SolverModel<Real>& model, const Attachment<Real>& attachment, const SimState& state,
                        StepScratch<Real>& scratch, size_t c);

// --- correction.cpp: the per-vertex pass ---
enum class VertexPass {
  kFromState,  // predict the first step of a frame from positions and velocities
  kStep,       // correct the step just matched (Eq. 7, mean of the corrections), predict the next
  kLastStep,   // kStep, and write positions and velocities; the prediction is the next frame's first
};
// Corrections of the matched step + the air of the next one => corrected vertices and the
// next step's prediction (state.prediction<Real>()): damping, gravity, global term (Eq. 8)
// and drag. Returns whether an island was asleep (its vertices were skipped). Throws
// SimulationError on a non-finite value or a runaway vertex.
template <typename Real>
bool correct_and_predict(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state,
                         StepScratch<Real>& scratch, VertexPass pass, long long frame, int substep);
// State at time t => the prediction of the first step from its positions and velocities.
template <typename Real>
void predict_from_state(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state,
                        StepScratch<Real>& scratch, long long frame);

// --- beam_statics.cpp ---
// The attachment's active members and flying clusters => its cluster_drag_area and
// cluster_drag_arm, summed along the cluster tree (children before parents).
template <typename Real>
void sum_drag_areas(const SolverModel<Real>& model, Attachment<Real>& attachment);
// Called by every thread of a parallel region (or outside one), after the step's drag
// (prediction.drag_force) is complete: the loads per cluster, summed and turned along the
// cluster tree => each cluster's turn and joint in the tree's static deflection
// (scratch.cluster_static_rotation, cluster_static_joint), complete for every thread on return.
template <typename Real>
void deflect_bar_chain(const SolverModel<Real>& model, const Attachment<Real>& attachment, const SimState& state,
                       StepScratch<Real>& scratch);
// The deflected chain => vertices [begin, end)'s offsets from rest in it (prediction.goal).
template <typename Real>
void write_static_offsets(const SolverModel<Real>& model, const Attachment<Real>& attachment,
                          const StepScratch<Real>& scratch, StepPrediction<Real>& prediction, size_t begin,
                          size_t end);

// --- shape_matching.cpp ---
// Predicted positions => rotations, shifts and per-membership corrections of every awake
// cluster: branches and free leaves, then the attached leaves (attached_leaves.cpp), each
// cluster followed by its air for the next step (at the time in scratch.air). Throws
// SimulationError naming the lowest cluster whose fit is not finite.
template <typename Real>
void match_clusters(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state,
                    StepScratch<Real>& scratch, long long frame, int substep);

// --- attached_leaves.cpp ---
// Inside match_clusters' parallel region, after a barrier: the attached leaves, each fitted
// about its shared vertex held at its branch's goal. Lowers `bad` to a failing cluster.
template <typename Real>
void match_attached_leaves(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state,
                           StepScratch<Real>& scratch, uint32_t& bad);

// --- detachment.cpp ---
// state.leaf_attached => `attachment` built for exactly those flags (unchanged when they
// already match). Throws SimulationError when the state has another leaf count.
template <typename Real>
void adopt_leaf_flags(const SolverModel<Real>& model, const SimState& state, Attachment<Real>& attachment);
// Predicted drag on each attached leaf => the leaves past leaf_detach_force detach (in leaf
// order): state.leaf_attached and the attachment change.
template <typename Real>
void detach_leaves(const SolverModel<Real>& model, Attachment<Real>& attachment, SimState& state,
                   StepScratch<Real>& scratch);

// --- sleeping.cpp ---
// Frame from `start`: every island wakes when the air moves at any of its steps => false
// when nothing needs to step (every island asleep, no leaf flying).
template <typename Real>
bool wake_islands(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state, double start);
// End of a frame: awake islands in calm air whose vertices all rest are put to sleep exactly
// at their rest pose => true when one was.
template <typename Real>
bool fall_asleep(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state,
                 StepScratch<Real>& scratch);

}  // namespace treeanim
