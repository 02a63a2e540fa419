// Attached leaves (docs/solver.md, "Leaves"): a leaf is a rigid body pinned at its shared
// (petiole) vertex, which is held at its branch's goal for it; the leaf turns about that
// vertex, its joint in the bar chain, and its drag loads its branch through the chain
// (beam_statics.cpp), not through the branch's fit.
#include "sim/kernel_isa.h"
#include "sim/shape_matching.h"

namespace treeanim {

template <typename Real>
Eigen::Vector3d held_point(const SolverModel<Real>& model, const Attachment<Real>& attachment, const SimState& state,
                           const StepScratch<Real>& scratch, uint32_t c) {
  // The shared vertex's goal in its branch b, t0_b + shift_b + R_b q_b, as a displacement
  // from its rest position t0_b + q_b: shift_b + (R_b - I) q_b, written without the rest
  // terms that cancel (their round-off would pull every resting leaf).
  const uint32_t pin = attachment.cluster_pin_slot[c];
  const uint32_t branch = model.tree.member_cluster[pin];
  const Eigen::Vector3d branch_offset = attachment.member_offset.row(pin).transpose().template cast<double>();
  return state.cluster_shift.col(branch) +
         (Eigen::Map<const Eigen::Matrix3d>(&scratch.cluster_rotation_matrix(0, branch)) * branch_offset - branch_offset);
}

// Runs as an orphaned worksharing loop inside match_clusters' parallel region, after the
// branches' fits (their rotations in the scratch, their shifts in the state) are complete;
// the leaves sampled their air there.
template <typename Real>
void match_attached_leaves(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state,
                           StepScratch<Real>& scratch, uint32_t& bad) {
  const std::vector<uint32_t>& leaves = model.pinned_leaf_clusters;
  const size_t groups = (leaves.size() + kMatchLanes - 1) / kMatchLanes;
#pragma omp for schedule(static)
  for (size_t g = 0; g < groups; ++g) {
    MatchLanes<Real> lanes(model, attachment, state, scratch, true, false);
    with_kernel_isa([&] {
      for (size_t k = g * kMatchLanes; k < std::min(leaves.size(), (g + 1) * kMatchLanes); ++k) {
        const uint32_t c = leaves[k];
        if (attachment.cluster_pin_slot[c] != kNone && cluster_awake(model, attachment, state, c)) lanes.add(c);
      }
      lanes.flush();
    });
    bad = std::min(bad, lanes.bad());
  }
}

template Eigen::Vector3d held_point(const SolverModel<float>&, const Attachment<float>&, const SimState&,
                                    const StepScratch<float>&, uint32_t);
template Eigen::Vector3d held_point(const SolverModel<double>&, const Attachment<double>&, const SimState&,
                                    const StepScratch<double>&, uint32_t);
template void match_attached_leaves(const SolverModel<float>&, const Attachment<float>&, SimState&,
                                    StepScratch<float>&, uint32_t&);
template void match_attached_leaves(const SolverModel<double>&, const Attachment<double>&, SimState&,
                                    StepScratch<double>&, uint32_t&);

}  // namespace treeanim
