// The static deflection of the branches under the step's loads (docs/solver.md, "Bending"):
// the tree as a chain of rigid clusters joined by rotational springs (a Hencky bar chain,
// the discrete Euler-Bernoulli beam), solved exactly in two passes over the cluster tree.
// The global term pulls every vertex toward this deflected pose instead of its rest
// position, so loads bend a branch from its root, as they bend a beam.
#include <omp.h>

#include <Eigen/Geometry>

#include "sim/solver_step.h"

namespace treeanim {

namespace {

// Rotation vector => rotation matrix (exact for any angle; the identity at 0).
Eigen::Matrix3d rotation_of(const Eigen::Vector3d& theta) {
  const double angle = theta.norm();
  if (!(angle > 0)) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, theta / angle).toRotationMatrix();
}

}  // namespace

template <typename Real>
void compute_static_offsets(const SolverModel<Real>& model, const Attachment<Real>& attachment,
                            SimState& state, StepScratch<Real>& scratch) {
  const TreeModel& tree = model.tree;
  StepPrediction<Real>& prediction = state.prediction<Real>();
  const size_t C = model.C;
  // 1. Per cluster: its members' share of the loads, and their moment about its joint. The
  // arms are those of the rest pose: the goal is then a linear function of the loads, with a
  // potential, where arms of the current pose made it a follower load that chased a bent
  // limb round in circles (docs/solver.md, "Bending"); the yield turn bounds large loads.
  const Eigen::Matrix3Xd& joint = model.chain.cluster_joint;
#pragma omp parallel for schedule(static) if (model.parallel)
  for (size_t c = 0; c < C; ++c) {
    Eigen::Vector3d force = Eigen::Vector3d::Zero(), moment = Eigen::Vector3d::Zero();
    if (!attachment.cluster_flying[c])
      for (uint32_t s = tree.cluster_offsets[c]; s < tree.cluster_offsets[c + 1]; ++s) {
        if (!attachment.member_active[s]) continue;
        const uint32_t v = tree.cluster_members[s];
        const Eigen::Vector3d f = prediction.drag_force.row(v).transpose().template cast<double>() *
                                  double(attachment.vertex_inv_count[v]);
        force += f;
        moment += (tree.rest_positions.col(v) - joint.col(c)).cross(f);
      }
    scratch.cluster_load.col(c) = force;
    scratch.cluster_moment.col(c) = moment;
  }
  // 2. Children before parents: a joint carries the moment of everything beyond it.
  for (size_t c = C; c-- > 0;) {
    const int32_t p = tree.cluster_parent[c];
    if (p < 0 || attachment.cluster_flying[c]) continue;
    scratch.cluster_load.col(p) += scratch.cluster_load.col(c);
    scratch.cluster_moment.col(p) += scratch.cluster_moment.col(c) + (joint.col(c) - joint.col(p)).cross(scratch.cluster_load.col(c));
  }
  // 3. Parents before children: each joint turns by its compliance times its moment, and the
  // turns accumulate from the root.
  for (size_t c = 0; c < C; ++c) {
    const int32_t p = tree.cluster_parent[c];
    Eigen::Map<Eigen::Matrix3d> R(&scratch.cluster_static_rotation(0, c));
    Eigen::Vector3d theta = model.chain.cluster_compliance[c] * scratch.cluster_moment.col(c);
    const double angle = theta.norm(), largest = model.chain.cluster_max_turn[c];
    if (angle > largest) theta *= largest / angle;
    const Eigen::Matrix3d turn = rotation_of(theta);
    if (p < 0 || attachment.cluster_flying[c]) {
      R = turn;
      scratch.cluster_static_joint.col(c) = joint.col(c);
      continue;
    }
    const Eigen::Map<const Eigen::Matrix3d> parent(&scratch.cluster_static_rotation(0, p));
    scratch.cluster_static_joint.col(c) =
        scratch.cluster_static_joint.col(p) + parent * (joint.col(c) - joint.col(p));
    R = turn * parent;
  }
  // 4. Per vertex: the mean over its clusters of their deflected poses, as an offset from rest.
#pragma omp parallel for schedule(static) if (model.parallel)
  for (size_t v = 0; v < model.V; ++v) {
    Eigen::Vector3d offset = Eigen::Vector3d::Zero();
    const Eigen::Vector3d x0 = tree.rest_positions.col(v);
    for (uint32_t s = tree.vertex_cluster_offsets[v]; s < tree.vertex_cluster_offsets[v + 1]; ++s) {
      const uint32_t slot = tree.vertex_memberships[s], c = model.member_cluster[slot];
      if (!attachment.member_active[slot]) continue;
      const Eigen::Map<const Eigen::Matrix3d> R(&scratch.cluster_static_rotation(0, c));
      offset += R * (x0 - joint.col(c)) + scratch.cluster_static_joint.col(c) - x0;
    }
    prediction.goal.row(v) = (offset * double(attachment.vertex_inv_count[v])).transpose().template cast<Real>();
  }
}

template void compute_static_offsets(const SolverModel<float>&, const Attachment<float>&, SimState&,
                                     StepScratch<float>&);
template void compute_static_offsets(const SolverModel<double>&, const Attachment<double>&, SimState&,
                                     StepScratch<double>&);

}  // namespace treeanim
