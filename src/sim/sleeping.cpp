// Sleeping islands (docs/solver.md, "Sleeping"; Box2D's solver sets): an island at rest in
// calm air costs nothing until the air moves.
#include <Eigen/Geometry>
#include <algorithm>

#include "sim/solver_step.h"

namespace treeanim {

template <typename Real>
bool wake_islands(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state, double start) {
  bool calm = true;
  for (int k = 0; k < model.substeps && calm; ++k) calm = model.wind.calm(start + k * model.h);
  if (!calm) std::fill(state.island_asleep.begin(), state.island_asleep.end(), 0);
  const bool all_asleep =
      std::all_of(state.island_asleep.begin(), state.island_asleep.end(), [](uint8_t a) { return a != 0; });
  return !all_asleep ||
         std::any_of(attachment.cluster_flying.begin(), attachment.cluster_flying.end(), [](uint8_t f) { return f != 0; });
}

// An island is put to sleep at its rest pose, velocities 0 and rotations identity: where the
// awake solver converges anyway. Flying leaves never sleep.
template <typename Real>
bool fall_asleep(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state,
                 StepScratch<Real>& scratch) {
  if (!model.wind.calm(state.time)) return false;
  const TreeModel& tree = model.tree;
  bool fell_asleep = false;
  const double v2 = model.options.sleep_velocity * model.options.sleep_velocity;
  const double d2 = model.options.sleep_distance * model.options.sleep_distance;
  for (size_t i = 0; i < model.I; ++i) {
    if (state.island_asleep[i]) continue;
    bool rests = true;
    for (uint32_t k = model.island_vertex_offsets[i]; rests && k < model.island_vertex_offsets[i + 1]; ++k) {
      const uint32_t v = model.island_vertices[k];
      if (attachment.vertex_flying[v]) continue;
      rests = state.velocities.col(v).squaredNorm() < v2 &&
              (state.positions.col(v) - tree.rest_positions.col(v)).squaredNorm() < d2;
    }
    if (!rests) continue;
    state.island_asleep[i] = 1;
    fell_asleep = true;
    scratch.island_fell_asleep[i] = 1;
    for (uint32_t k = model.island_vertex_offsets[i]; k < model.island_vertex_offsets[i + 1]; ++k) {
      const uint32_t v = model.island_vertices[k];
      if (attachment.vertex_flying[v]) continue;
      state.positions.col(v) = tree.rest_positions.col(v);
      state.velocities.col(v).setZero();
    }
  }
  // At the rest pose every rotation is the identity (exactly: A_pq is symmetric there).
  for (size_t c = 0; c < model.C; ++c)
    if (scratch.island_fell_asleep[model.cluster_island[c]] && !attachment.cluster_flying[c])
      state.cluster_rotations.col(c) = Eigen::Quaterniond::Identity().coeffs();
  std::fill(scratch.island_fell_asleep.begin(), scratch.island_fell_asleep.end(), 0);
  return fell_asleep;
}

template bool wake_islands(const SolverModel<float>&, const Attachment<float>&, SimState&, double);
template bool wake_islands(const SolverModel<double>&, const Attachment<double>&, SimState&, double);
template bool fall_asleep(const SolverModel<float>&, const Attachment<float>&, SimState&, StepScratch<float>&);
template bool fall_asleep(const SolverModel<double>&, const Attachment<double>&, SimState&, StepScratch<double>&);

}  // namespace treeanim
