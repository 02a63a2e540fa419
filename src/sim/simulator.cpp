// Simulator: the solver in the precision the options ask for; a frame is the step list of
// docs/solver.md, "One step", over (SolverModel, SimState, StepScratch).
#include "sim/simulator.h"

#include <Eigen/Geometry>
#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <optional>
#include <string>
#include <utility>

#include "common/errors.h"
#include "common/message_text.h"
#include "sim/solver_step.h"

namespace treeanim {

// What the Simulator forwards to: the solver in the precision the options ask for.
struct Simulator::Impl {
  virtual ~Impl() = default;
  virtual SimState initial_state(double time) const = 0;
  virtual void advance_frame(SimState& state, long long frame) = 0;
};

namespace {

template <typename Real>
struct Solver final : Simulator::Impl {
  const SolverModel<Real> model;
  Attachment<Real> attachment;  // for the leaf flags of the last state seen (adopt_leaf_flags)
  StepScratch<Real> scratch;

  Solver(const TreeModel& tree, const HsmOptions& options, const WindOptions& wind, double frame_dt, int substeps,
         size_t block_memberships)
      : model(tree, options, wind, frame_dt, substeps, block_memberships),
        attachment(model.all_attached),
        scratch(model) {}
  SimState initial_state(double time) const override;
  void advance_frame(SimState& state, long long frame) override;
  void adopt(SimState& state, long long frame);
};

template <typename Real>
SimState Solver<Real>::initial_state(double time) const {
  SimState state;
  state.positions = model.tree.rest_positions;
  state.velocities.setZero(3, model.V);
  state.leaf_attached.assign(model.L, 1);
  state.time = time;
  state.cluster_rotations.resize(4, model.C);
  for (size_t c = 0; c < model.C; ++c) state.cluster_rotations.col(c) = Eigen::Quaterniond::Identity().coeffs();
  state.cluster_shift.setZero(3, model.C);
  // At rest in calm air there is nothing to do until the wind rises.
  state.island_asleep.assign(model.I, model.options.sleep && model.wind.calm(time) ? 1 : 0);
  StepPrediction<Real>& prediction = state.prediction<Real>();
  prediction.offset.setZero(model.V, 3);
  prediction.velocity.setZero(model.V, 3);
  prediction.drag_force.setZero(model.store_drag_force ? model.V : 0, 3);
  prediction.goal.setZero(model.V, 3);
  prediction.damping_offset.setZero(model.V, 3);
  prediction.damping_compliance.setZero(model.V);
  return state;
}

// A state from elsewhere (a checkpoint, another simulator, a test) => checked against the
// model, its prediction arrays sized (without a prediction when they were not), and the
// attachment built for its leaf flags.
template <typename Real>
void Solver<Real>::adopt(SimState& state, long long frame) {
  if (state.positions.cols() != static_cast<Eigen::Index>(model.V) || state.leaf_attached.size() != model.L ||
      state.cluster_rotations.cols() != static_cast<Eigen::Index>(model.C) || state.island_asleep.size() != model.I)
    throw SimulationError("frame " + std::to_string(frame) + ": the state does not belong to this tree model");
  if (state.cluster_shift.cols() != static_cast<Eigen::Index>(model.C)) state.cluster_shift.setZero(3, model.C);
  StepPrediction<Real>& prediction = state.prediction<Real>();
  const auto rows = static_cast<Eigen::Index>(model.V);
  if (prediction.offset.rows() != rows || prediction.velocity.rows() != rows ||
      prediction.drag_force.rows() != (model.store_drag_force ? rows : 0) || prediction.goal.rows() != rows ||
      prediction.damping_offset.rows() != rows || prediction.damping_compliance.rows() != rows) {
    prediction.offset.setZero(rows, 3);
    prediction.velocity.setZero(rows, 3);
    prediction.drag_force.setZero(model.store_drag_force ? rows : 0, 3);
    prediction.goal.setZero(rows, 3);
    prediction.damping_offset.setZero(rows, 3);
    prediction.damping_compliance.setZero(rows);
    state.predicted = false;
  }
  adopt_leaf_flags(model, state, attachment);
}

template <typename Real>
void Solver<Real>::advance_frame(SimState& state, long long frame) {
  adopt(state, frame);
  const double start = state.time;
  const bool predicted = std::exchange(state.predicted, false);
  bool complete = false;  // the state ends with the next frame's first prediction
  // Sleeping islands wake as soon as the air moves at any step of this frame.
  if (!model.options.sleep || wake_islands(model, attachment, state, start)) {
    // 1-3. Load, bend and predict the first step, unless the frame that wrote the state did.
    if (!predicted) predict_from_state(model, attachment, state, scratch, frame);
    bool skipped_sleepers = false;
    for (int k = 0; k < model.substeps; ++k) {
      const bool last = k + 1 == model.substeps;
      // 6. Detach the leaves whose predicted drag passes the threshold.
      if (model.detach_enabled) detach_leaves(model, attachment, state, scratch);
      // 4. Match the clusters on the predicted positions, branches, then attached leaves;
      // each samples the air of the next step (after the last: the next frame's first).
      set_air_time(model, last ? start + model.frame_dt : start + (k + 1) * model.h, scratch);
      if (model.block_cluster_offsets.empty()) {
        match_clusters(model, attachment, state, scratch, frame, k);
        // 5, 1, 2, 3. Correct, load, bend and predict the next step; the last step writes the frame.
        skipped_sleepers = correct_and_predict(model, attachment, state, scratch,
                                               last ? VertexPass::kLastStep : VertexPass::kStep, frame, k);
      } else {
        // The same (3 of this step, 4, 5 and 1, then 2), block by block while each is in cache.
        skipped_sleepers =
            step_in_blocks(model, attachment, state, scratch, {.predict = k > 0, .last = last}, frame, k);
      }
    }
    complete = !skipped_sleepers;
  }
  state.time += model.frame_dt;
  // An island put to sleep is moved to its rest pose: the prediction no longer holds.
  if (model.options.sleep && fall_asleep(model, attachment, state, scratch)) complete = false;
  state.predicted = complete;
}

// A block's vertex, membership and cluster data (about 400 bytes a membership in float, 6.5 MB)
// stays in the cache between its passes, two threads' blocks at once in a 32 MiB L3
// (docs/solver.md, "Cache blocks", which measured 8,192 and 32,768 too).
constexpr size_t kBlockMemberships = 16384;

// Memberships a cache block may be asked for: more than any tree holds (a tree's memberships are
// 32-bit counts).
constexpr unsigned long long kMostBlockMemberships = 0xffffffffull;

// TREEANIM_BLOCKS => its count when it is one in 0 ... kMostBlockMemberships, else none.
std::optional<size_t> asked_blocks() {
  const char* asked = std::getenv("TREEANIM_BLOCKS");
  if (!asked || !std::isdigit(static_cast<unsigned char>(*asked))) return std::nullopt;
  errno = 0;
  char* end = nullptr;
  const unsigned long long n = std::strtoull(asked, &end, 10);
  if (*end != 0 || errno != 0 || n > kMostBlockMemberships) return std::nullopt;
  return size_t(n);
}

}  // namespace

size_t cache_block_memberships() {
  static const size_t memberships = asked_blocks().value_or(kBlockMemberships);
  return memberships;
}

std::string asked_blocks_error() {
  const char* asked = std::getenv("TREEANIM_BLOCKS");
  if (!asked || asked_blocks()) return "";
  return "TREEANIM_BLOCKS: expected a count of memberships, 0 ... " + std::to_string(kMostBlockMemberships) +
         " (0: no cache blocks; or none: " + std::to_string(kBlockMemberships) + "), got '" + excerpt(asked) + "'";
}

Simulator::Simulator(const TreeModel& model, const HsmOptions& options, const WindOptions& wind,
                     double frame_dt, int substeps, size_t block_memberships) {
  if (options.precision == Precision::kFloat)
    impl_ = std::make_unique<Solver<float>>(model, options, wind, frame_dt, substeps, block_memberships);
  else
    impl_ = std::make_unique<Solver<double>>(model, options, wind, frame_dt, substeps, block_memberships);
}

Simulator::~Simulator() = default;

SimState Simulator::initial_state(double time) const { return impl_->initial_state(time); }

void Simulator::advance_frame(SimState& state, long long frame) { impl_->advance_frame(state, frame); }

}  // namespace treeanim
