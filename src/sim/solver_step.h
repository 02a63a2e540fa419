#pragma once
// The phases of one frame (docs/solver.md, "One step"), free functions over the solver's
// model, the attachment it derives from the state, the state and the step's scratch. Each is
// defined in the file named after what it computes and instantiated for float and double.
#include <cstdint>
#include <span>
#include <utility>

#include "sim/solver_model.h"

namespace treeanim {

// --- air.cpp ---
// t => the wind terms every cluster shares at t (mean, gust, turbulence amplitude, phases),
// each wave averaged over the step h (WindField::sample_time); with a volume, its frames
// around t, sampled at the rest centres when they are new (outside parallel regions: it reads files).
template <typename Real>
void set_air_time(const SolverModel<Real>& model, double t, StepScratch<Real>& scratch);
// Cluster c + air at a time => scratch.cluster_air row c: at its rest centre, or for a
// flying leaf at the centre of its last fit (t0 + state.cluster_shift).
template <typename Real>
void sample_cluster_air(const SolverModel<Real>& model, const Attachment<Real>& attachment, const SimState& state,
                        StepScratch<Real>& scratch, size_t c);
// The same for clusters added one by one: those at their rest centres in air without a volume
// four at a time (WindField::velocities), to the same bits; the others as they come.
template <typename Real>
class AirLanes {
 public:
  AirLanes(const SolverModel<Real>& model, const Attachment<Real>& attachment, const SimState& state,
           StepScratch<Real>& scratch)
      : model_(model), attachment_(attachment), state_(state), scratch_(scratch) {}
  void add(uint32_t c);
  // The clusters added since the last flush => their air.
  void flush();

 private:
  const SolverModel<Real>& model_;
  const Attachment<Real>& attachment_;
  const SimState& state_;
  StepScratch<Real>& scratch_;
  uint32_t lane_[4];
  size_t count_ = 0;
};

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
// How a step's vertex passes run.
struct VertexPassMode {
  bool from_state = false;  // u and v loaded from the state: the prediction of a frame's first step
  bool last = false;        // a frame's last step: the corrected u and v kept for the state, the runaway checked
  bool any_asleep = false;  // islands asleep: each block of vertices gathered lane by lane
};
// The passes of correct_and_predict, called by each thread on its vertices [first, last),
// in a parallel region or outside one. The step just matched => the vertices corrected and
// the drag of the next step measured => the lowest vertex not finite and the lowest that
// ran away, each kNone for none.
template <typename Real>
std::pair<uint32_t, uint32_t> correct_vertices(const SolverModel<Real>& model, const Attachment<Real>& attachment,
                                               SimState& state, StepScratch<Real>& scratch, VertexPassMode mode,
                                               size_t first, size_t last);
// Corrected vertices (corrected here first, unless the frame's last step kept them) =>
// their goals (with the beam), after the chain's walk, and the next step's prediction => the
// lowest vertex not finite, kNone for none.
template <typename Real>
uint32_t predict_vertices(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state,
                          StepScratch<Real>& scratch, VertexPassMode mode, size_t first, size_t last);
// The corrected vertices [first, last) (prediction) => the state's positions and velocities,
// in double; a vertex that does not move keeps its values.
template <typename Real>
void write_state(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state,
                 bool any_asleep, size_t first, size_t last);
// The lowest vertex found not finite, and the lowest that ran away (kNone: none) => the
// SimulationError naming the first, else the second; nothing when both are kNone.
template <typename Real>
void throw_vertex_failure(const SolverModel<Real>& model, const Attachment<Real>& attachment, const SimState& state,
                          long long frame, int substep, uint32_t bad, uint32_t runaway);
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
// The same in two parts, for a step that sums a cluster's loads as soon as its members are
// corrected (cache_blocks.cpp): the loads of the listed clusters; and, called by every thread
// of a parallel region once every cluster's loads are summed, the rest.
template <typename Real>
void sum_cluster_loads(const SolverModel<Real>& model, const Attachment<Real>& attachment, const SimState& state,
                       StepScratch<Real>& scratch, std::span<const uint32_t> clusters);
template <typename Real>
void walk_bar_chain(const SolverModel<Real>& model, const Attachment<Real>& attachment, StepScratch<Real>& scratch);
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

// The listed clusters in order (a cache block's: branches, then the leaves pinned to them) =>
// each awake one matched (an attached leaf about its shared vertex, its branch listed before
// it) and its air for the next step => the lowest cluster whose fit is not finite, kNone for none.
template <typename Real>
uint32_t match_listed_clusters(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state,
                               StepScratch<Real>& scratch, std::span<const uint32_t> clusters);
// The lowest cluster whose fit is not finite => the SimulationError naming it.
[[noreturn]] void throw_match_failure(long long frame, int substep, uint32_t cluster);

// --- attached_leaves.cpp ---
// Inside match_clusters' parallel region, after a barrier: the attached leaves, each fitted
// about its shared vertex held at its branch's goal. Lowers `bad` to a failing cluster.
template <typename Real>
void match_attached_leaves(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state,
                           StepScratch<Real>& scratch, uint32_t& bad);

// --- cache_blocks.cpp ---
// Where a step in blocks stands in its frame.
struct BlockStep {
  bool predict = false;  // predict the step from the one before (false for a frame's first step)
  bool last = false;     // a frame's last step
};
// One step in the model's cache blocks (SolverModel::block_cluster_offsets), in place of
// match_clusters and correct_and_predict: unless it is a frame's first step (`predict` false:
// the frame before or predict_from_state predicted it), the step predicted from the one
// before; then block by block its vertices matched, corrected and their clusters' loads
// summed, the border's after the blocks, and the chain's walk; a frame's `last` step writes
// the state and predicts the next frame's first. Returns whether an island was asleep. Throws
// the SimulationError those two would have, in the substep they would have thrown it.
template <typename Real>
bool step_in_blocks(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state,
                    StepScratch<Real>& scratch, BlockStep step, long long frame, int substep);

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
