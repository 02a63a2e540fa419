#pragma once
// The phases of one frame (docs/solver.md, "One step"), free functions over the solver's
// model, the attachment it derives from the state, the state and the step's scratch. Each is
// defined in the file named after what it computes and instantiated for float and double.
#include <cstdint>

#include "sim/solver_model.h"

namespace treeanim {

// Where the goals of vertices [first, ...) are written or read: vertex v's goal offset and
// damping compliance at index v - first (the prediction's rows, or a block's own buffer).
template <typename Real>
struct GoalRows {
  Real *x, *y, *z, *compliance;
  size_t first;
};
// The prediction's goal rows from vertex `first`.
template <typename Real>
inline GoalRows<Real> goal_rows(StepPrediction<Real>& prediction, size_t first) {
  return {prediction.goal.col(0).data() + first, prediction.goal.col(1).data() + first,
          prediction.goal.col(2).data() + first, prediction.damping_compliance.data() + first, first};
}

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
// Inside a parallel region, every thread, once the corrections and loads are complete: the
// state's write (kLastStep) of vertices [first, last), the bar chain's passes, and the next
// step's prediction of those vertices => the lowest vertex whose prediction is not finite.
template <typename Real>
uint32_t deflect_and_predict(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state,
                             StepScratch<Real>& scratch, size_t first, size_t last, bool any_asleep, VertexPass pass);
// The lowest vertex with a non-finite value (bad) or past the runaway limit, kNone for none =>
// SimulationError naming it, frame and substep (nothing when both are kNone).
template <typename Real>
void throw_vertex_fault(const SolverModel<Real>& model, const Attachment<Real>& attachment, const SimState& state,
                        long long frame, int substep, uint32_t bad, uint32_t runaway);
// State at time t => the prediction of the first step from its positions and velocities.
template <typename Real>
void predict_from_state(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state,
                        StepScratch<Real>& scratch, long long frame);

// --- cluster_sweep.cpp ---
// A substep as one sweep over the clusters (docs/solver.md, "One sweep"): the prediction
// (unless `predicted`: the first step of a frame, predicted by the frame before or from the
// state), the match, the correction and the next step's loads, then the bar chain; the last
// step of a frame (`end`) writes the state and predicts the next frame's first step. The
// bytes of match_clusters + correct_and_predict, for a frame with no island asleep and no
// leaf that may detach. Throws SimulationError as they do.
template <typename Real>
void sweep_clusters(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state,
                    StepScratch<Real>& scratch, bool predicted, bool end, long long frame, int substep);

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
// The deflected chain => vertices [begin, end)'s offsets from rest in it and their damping
// compliances, into `out`.
template <typename Real>
void write_static_offsets(const SolverModel<Real>& model, const Attachment<Real>& attachment,
                          const StepScratch<Real>& scratch, const GoalRows<Real>& out, size_t begin, size_t end);

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
