// Leaf detachment (paper 4.2; docs/solver.md, "Leaves"): past leaf_detach_force a leaf
// leaves its branch and flies on as a free, still shape-matched rigid leaf.
#include <string>

#include "common/errors.h"
#include "sim/solver_step.h"

namespace treeanim {

namespace {

// Releases leaf `leaf` from its branch: the shared vertex stays with the side it was built
// for (a leaf vertex leaves its branch clusters; a branch vertex leaves the leaf), the
// clusters that lost a member get new rest data, and the leaf's vertices fly. The result
// depends only on which leaves are detached, not on the order.
template <typename Real>
void detach_leaf(const SolverModel<Real>& model, Attachment<Real>& a, size_t leaf, Rows3<Real>* corrections) {
  const TreeModel& tree = model.tree;
  const uint32_t c = tree.leaf_cluster[leaf];
  const uint32_t shared = tree.leaf_attachment_vertex[leaf];
  const bool goes_with_leaf = tree.vertex_leaf[shared] == static_cast<int32_t>(leaf);
  for (uint32_t s = tree.vertex_cluster_offsets[shared]; s < tree.vertex_cluster_offsets[shared + 1]; ++s) {
    const uint32_t slot = tree.vertex_memberships[s];
    const uint32_t owner = model.tree.member_cluster[slot];
    if ((owner == c) == goes_with_leaf || !a.member_active[slot]) continue;
    a.member_active[slot] = 0;
    a.member_in_fit[slot] = 0;
    a.cluster_released[owner] = 1;
    if (corrections) corrections->row(model.member_correction_row[slot]).setZero();
    if (owner != c) rebuild_cluster_rest(model, a, owner);
  }
  a.cluster_pin_slot[c] = kNone;  // a flying leaf turns about its centre: new rest data, once
  rebuild_cluster_rest(model, a, c);
  // The shared vertex feels the air of its first cluster that still holds it.
  uint32_t active = 0, first = kNone;
  for (uint32_t s = tree.vertex_cluster_offsets[shared]; s < tree.vertex_cluster_offsets[shared + 1]; ++s) {
    const uint32_t slot = tree.vertex_memberships[s];
    if (!a.member_active[slot]) continue;
    if (active++ == 0) first = slot;
  }
  a.vertex_inv_count[shared] = active ? Real(1.0 / active) : Real(0.0);
  if (first != kNone) a.vertex_air_cluster[shared] = model.tree.member_cluster[first];
  a.cluster_flying[c] = 1;
  for (uint32_t s = tree.cluster_offsets[c]; s < tree.cluster_offsets[c + 1]; ++s) {
    const uint32_t v = tree.cluster_members[s];
    if (!a.member_active[s] || tree.vertex_leaf[v] != static_cast<int32_t>(leaf) || tree.vertex_anchored[v]) continue;
    a.vertex_flying[v] = 1;
    a.vertex_global[v] = 0;  // the rest pose no longer holds a flying leaf
    a.vertex_half_damping[v] = 1;  // nor does a limb's damping: gravity and drag alone act on its flight
    a.vertex_kick_scale[v] = 1;
  }
  a.leaf_attached[leaf] = 0;
}

}  // namespace

template <typename Real>
void adopt_leaf_flags(const SolverModel<Real>& model, const SimState& state, Attachment<Real>& attachment) {
  if (state.leaf_attached == attachment.leaf_attached) return;
  if (state.leaf_attached.size() != model.L)
    throw SimulationError("the state has " + std::to_string(state.leaf_attached.size()) + " leaf flags, the tree " +
                          std::to_string(model.L) + " leaves");
  attachment = model.all_attached;
  for (size_t l = 0; l < model.L; ++l)
    if (!state.leaf_attached[l]) detach_leaf<Real>(model, attachment, l, nullptr);
  sum_drag_areas(model, attachment);
}

// The drag on a leaf is summed over its own vertices in membership order (fixed order). A leaf
// held by the ground (drawn before any segment: its petiole is anchored where it was drawn)
// never lets go: an anchored vertex cannot fly, and a leaf flying from it would stretch.
template <typename Real>
void detach_leaves(const SolverModel<Real>& model, Attachment<Real>& attachment, SimState& state,
                   StepScratch<Real>& scratch) {
  const TreeModel& tree = model.tree;
  const Rows3<Real>& drag_force = state.prediction<Real>().drag_force;
  bool detached = false;
  for (size_t l = 0; l < model.L; ++l) {
    if (!state.leaf_attached[l] || tree.vertex_anchored[tree.leaf_attachment_vertex[l]]) continue;
    const uint32_t c = tree.leaf_cluster[l];
    Eigen::Vector3d force = Eigen::Vector3d::Zero();
    for (uint32_t s = tree.cluster_offsets[c]; s < tree.cluster_offsets[c + 1]; ++s) {
      const uint32_t v = tree.cluster_members[s];
      if (tree.vertex_leaf[v] == static_cast<int32_t>(l)) force += drag_force.row(v).transpose().template cast<double>();
    }
    if (force.norm() > model.options.leaf_detach_force) {
      detach_leaf(model, attachment, l, &scratch.member_correction);
      state.leaf_attached[l] = 0;
      detached = true;
    }
  }
  if (detached) sum_drag_areas(model, attachment);
}

template void adopt_leaf_flags(const SolverModel<float>&, const SimState&, Attachment<float>&);
template void adopt_leaf_flags(const SolverModel<double>&, const SimState&, Attachment<double>&);
template void detach_leaves(const SolverModel<float>&, Attachment<float>&, SimState&, StepScratch<float>&);
template void detach_leaves(const SolverModel<double>&, Attachment<double>&, SimState&, StepScratch<double>&);

}  // namespace treeanim
