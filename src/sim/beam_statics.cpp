// The static deflection of the branches under the step's loads (docs/solver.md, "Bending"):
// the tree as a chain of rigid clusters joined by rotational springs (a Hencky bar chain,
// the discrete Euler-Bernoulli beam), solved exactly in two passes over the cluster tree.
// The global term pulls every vertex toward this deflected pose instead of its rest
// position, so loads bend a branch from its root, as they bend a beam.
#include <omp.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>

#include "sim/lanes.h"
#include "sim/solver_step.h"

namespace treeanim {

namespace {

// Rotation vector => rotation matrix (exact for any angle; the identity at 0).
Eigen::Matrix3d rotation_of(const Eigen::Vector3d& theta) {
  const double angle = theta.norm();
  if (!(angle > 0)) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, theta / angle).toRotationMatrix();
}

// A joint's turn => the same turn, at most `largest` long (its yield turn).
Eigen::Vector3d capped_turn(const Eigen::Vector3d& theta, double largest) {
  const double angle = theta.norm();
  return angle > largest ? Eigen::Vector3d(theta * (largest / angle)) : theta;
}

// The air the step's averages left out (AirSample::unresolved) => the six points of an
// unscented transform about the air, +- sqrt(3) sigma_k (sum of sigma_k sigma_k^T: the
// covariance). false when nothing is left out.
bool unresolved_points(const AirSample& air, Eigen::Vector3d (&point)[6]) {
  if (!(air.unresolved.trace() > 0)) return false;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
  eigen.computeDirect(air.unresolved);
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d sigma = std::sqrt(3 * std::max(eigen.eigenvalues()[k], 0.0)) * eigen.eigenvectors().col(k);
    point[2 * k] = sigma;
    point[2 * k + 1] = -sigma;
  }
  return true;
}

// A joint's turn under the step's mean loads, the load beyond it and its drag per unit |u| u
// (area) with that drag's moment times the compliance (reach), the unscented points and the
// yield turn => the mean of its turns at the points, each at most the yield turn. The loads
// beyond the joint are |u| u per unit area for one relative air u (the velocity's drag
// included); each point changes that air and so |u| u, quadratically. A load that swings
// within the step past the yield turn and across it bends the joint less than its mean
// would; below yield the mean keeps the quadratic drag's second-order rise.
Eigen::Vector3d mean_yielded_turn(const Eigen::Vector3d& theta, const Eigen::Vector3d& load, double area,
                                  const Eigen::Vector3d& reach, const Eigen::Vector3d (&point)[6], double largest) {
  if (!(area > 0)) return capped_turn(theta, largest);
  const Eigen::Vector3d g = load / area;
  const double size = std::sqrt(g.norm());
  const Eigen::Vector3d u = size > 0 ? Eigen::Vector3d(g / size) : Eigen::Vector3d::Zero();
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& d : point) {
    const Eigen::Vector3d air = u + d;
    sum += capped_turn(theta + reach.cross(air.norm() * air - g), largest);
  }
  return sum / 6;
}

}  // namespace

template <typename Real>
void sum_drag_areas(const SolverModel<Real>& model, Attachment<Real>& attachment) {
  const TreeModel& tree = model.tree;
  const Eigen::Matrix3Xd& joint = model.chain.cluster_joint;
  attachment.cluster_drag_area.assign(model.C, 0);
  attachment.cluster_drag_arm.setZero(3, model.C);
  for (size_t c = 0; c < model.C; ++c) {
    if (attachment.cluster_flying[c]) continue;
    // {area, arm x}, {arm y, z} in pairs, as the step's load sums (lanes.h)
    Pair area_arm_x = {0, 0}, arm_yz = {0, 0};
    for (uint32_t s = tree.cluster_offsets[c]; s < tree.cluster_offsets[c + 1]; ++s) {
      if (!attachment.member_active[s]) continue;
      const uint32_t v = tree.cluster_members[s];
      const double a = double(model.vertex_drag[v]) * tree.vertex_mass[v] * double(attachment.vertex_inv_count[v]);
      const double ax = tree.rest_positions(0, v) - joint(0, c), ay = tree.rest_positions(1, v) - joint(1, c),
                   az = tree.rest_positions(2, v) - joint(2, c);
      area_arm_x += Pair{1, ax} * a, arm_yz += Pair{ay, az} * a;
    }
    attachment.cluster_drag_area[c] = area_arm_x[0];
    attachment.cluster_drag_arm.col(c) = Eigen::Vector3d(area_arm_x[1], arm_yz[0], arm_yz[1]);
  }
  for (size_t c = model.C; c-- > 0;) {
    const int32_t p = tree.cluster_parent[c];
    if (p < 0 || attachment.cluster_flying[c]) continue;
    attachment.cluster_drag_area[p] += attachment.cluster_drag_area[c];
    attachment.cluster_drag_arm.col(p) +=
        attachment.cluster_drag_arm.col(c) + (joint.col(c) - joint.col(p)) * attachment.cluster_drag_area[c];
  }
}

template <typename Real>
void deflect_bar_chain(const SolverModel<Real>& model, const Attachment<Real>& attachment, const SimState& state,
                       StepScratch<Real>& scratch) {
  const TreeModel& tree = model.tree;
  const StepPrediction<Real>& prediction = state.prediction<Real>();
  const size_t C = model.C;
  // 1. Per cluster: its members' share of the loads, and their moment about its joint. The
  // arms are those of the rest pose: the goal is then a linear function of the loads, with a
  // potential, where arms of the current pose made it a follower load that chased a bent
  // limb round in circles (docs/solver.md, "Bending"); the yield turn bounds large loads.
  // Each thread sums the clusters whose vertices it corrected (balanced_range), in its cache.
  // Written out on raw arrays, f = F_v / k_v and moment += (x0 - joint) x f as Eigen
  // evaluates them, operation for operation.
  const Eigen::Matrix3Xd& joint = model.chain.cluster_joint;
  const Real *fx = prediction.drag_force.col(0).data(), *fy = prediction.drag_force.col(1).data(),
             *fz = prediction.drag_force.col(2).data();
  const double* rest = tree.rest_positions.data();
  const uint32_t* members = tree.cluster_members.data();
  const uint8_t* active = attachment.member_active.data();
  const Real* inv_count = attachment.vertex_inv_count.data();
  const Real* drag_damping = scratch.vertex_drag_damping.data();
  Eigen::Vector3d unresolved[6];
  const bool averaged = unresolved_points(scratch.air, unresolved);
  const auto [first, last] = balanced_range(tree.cluster_offsets, omp_get_thread_num(), omp_get_num_threads());
  // The ten sums in pairs (lanes.h), an SSE register each.
  for (size_t c = first; c < last; ++c) {
    // {force x, y}, {force z, damping}, {moment x, y}, {lever x, y}, {moment z, lever z}. The
    // damping: the same vertices' 2 D (the largest rate at which the quadratic drag changes
    // with the velocity) and its moment about the joint, the chain's aerodynamic damping.
    Pair force_xy = {0, 0}, force_z_damping = {0, 0}, moment_xy = {0, 0}, lever_xy = {0, 0}, z = {0, 0};
    const double jx = joint(0, c), jy = joint(1, c), jz = joint(2, c);
    if (!attachment.cluster_flying[c])
      for (uint32_t s = tree.cluster_offsets[c]; s < tree.cluster_offsets[c + 1]; ++s) {
        if (!active[s]) continue;
        const uint32_t v = members[s];
        const double share = double(inv_count[v]);
        const Pair g_xy = Pair{double(fx[v]), double(fy[v])} * share;
        const Pair g_z_d = Pair{double(fz[v]), 2 * double(drag_damping[v])} * share;
        force_xy += g_xy, force_z_damping += g_z_d;
        const double gx = g_xy[0], gy = g_xy[1], gz = g_z_d[0], d = g_z_d[1];
        const double ax = rest[3 * size_t(v)] - jx, ay = rest[3 * size_t(v) + 1] - jy, az = rest[3 * size_t(v) + 2] - jz;
        moment_xy += Pair{ay, az} * Pair{gz, gx} - Pair{az, ax} * Pair{gy, gz};
        lever_xy += Pair{ax, ay} * d;
        z += Pair{ax * gy - ay * gx, d * az};
      }
    scratch.cluster_load.col(c) = Eigen::Vector3d(force_xy[0], force_xy[1], force_z_damping[0]);
    scratch.cluster_moment.col(c) = Eigen::Vector3d(moment_xy[0], moment_xy[1], z[0]);
    scratch.cluster_damping[c] = force_z_damping[1];
    scratch.cluster_damping_moment.col(c) = Eigen::Vector3d(lever_xy[0], lever_xy[1], z[1]);
  }
#pragma omp barrier
  // 2. Children before parents: a joint carries the moment of everything beyond it.
#pragma omp single
  for (size_t c = C; c-- > 0;) {
    const int32_t p = tree.cluster_parent[c];
    if (p < 0 || attachment.cluster_flying[c]) continue;
    scratch.cluster_load.col(p) += scratch.cluster_load.col(c);
    scratch.cluster_moment.col(p) += scratch.cluster_moment.col(c) + (joint.col(c) - joint.col(p)).cross(scratch.cluster_load.col(c));
    scratch.cluster_damping[p] += scratch.cluster_damping[c];
    scratch.cluster_damping_moment.col(p) +=
        scratch.cluster_damping_moment.col(c) + (joint.col(c) - joint.col(p)) * scratch.cluster_damping[c];
  }
  // 3. Parents before children: each joint turns by its compliance times its moment (in
  // parallel: the sines and cosines), and the turns accumulate from the root (one thread),
  // as do the damping's sums over the joints from the root, C_j S_j and C_j S_j . (j_c - j_j)
  // (about the cluster's own joint: small numbers wherever the tree stands).
#pragma omp for schedule(static)
  for (size_t c = 0; c < C; ++c) {
    const double compliance = model.chain.cluster_compliance[c];
    const Eigen::Vector3d loaded = compliance * scratch.cluster_moment.col(c);
    const double angle = loaded.norm(), largest = model.chain.cluster_max_turn[c];
    // The damping's own term C_j S_j, with the compliance a joint at its yield turn has left
    // for a moment across its turn (none along it): a yielded joint does not move back.
    const double give = angle > largest ? largest / angle : 1.0;
    const Eigen::Vector3d theta =
        averaged ? mean_yielded_turn(loaded, scratch.cluster_load.col(c), attachment.cluster_drag_area[c],
                                     compliance * attachment.cluster_drag_arm.col(c), unresolved, largest)
                 : capped_turn(loaded, largest);
    scratch.cluster_damping_path.col(c) = (compliance * give) * scratch.cluster_damping_moment.col(c);
    Eigen::Map<Eigen::Matrix3d>(&scratch.cluster_static_rotation(0, c)) = rotation_of(theta);
  }
#pragma omp single
  for (size_t c = 0; c < C; ++c) {
    const int32_t p = tree.cluster_parent[c];
    Eigen::Map<Eigen::Matrix3d> R(&scratch.cluster_static_rotation(0, c));
    if (p < 0 || attachment.cluster_flying[c]) {
      scratch.cluster_static_joint.col(c) = joint.col(c);
      scratch.cluster_damping_lever[c] = 0;
      continue;
    }
    scratch.cluster_damping_path.col(c) += scratch.cluster_damping_path.col(p);
    scratch.cluster_damping_lever[c] =
        scratch.cluster_damping_lever[p] + scratch.cluster_damping_path.col(p).dot(joint.col(c) - joint.col(p));
    const Eigen::Matrix3d turn = R;
    const Eigen::Map<const Eigen::Matrix3d> parent(&scratch.cluster_static_rotation(0, p));
    scratch.cluster_static_joint.col(c) =
        scratch.cluster_static_joint.col(p) + parent * (joint.col(c) - joint.col(p));
    R = turn * parent;
  }
}

namespace {

// One cluster's deflected pose, read once per membership or once per run of its vertices.
struct DeflectedCluster {
  double R[9];      // its turn, column-major
  double moved[3];  // m, its joint in the static deflection
  double joint[3];  // m, its joint at rest
  double path[3];   // s/m, cluster_damping_path
  double lever;     // s, cluster_damping_lever
};

template <typename Real>
DeflectedCluster deflected_cluster(const SolverModel<Real>& model, const StepScratch<Real>& scratch, size_t c) {
  DeflectedCluster k;
  for (int i = 0; i < 9; ++i) k.R[i] = scratch.cluster_static_rotation(i, c);
  for (int i = 0; i < 3; ++i) {
    k.moved[i] = scratch.cluster_static_joint(i, c);
    k.joint[i] = model.chain.cluster_joint(i, c);
    k.path[i] = scratch.cluster_damping_path(i, c);
  }
  k.lever = scratch.cluster_damping_lever[c];
  return k;
}

// Rest point (x, y, z) in cluster k => its offset from rest in the deflected pose,
// R (x0 - joint) + static joint - x0, and sum_j C_j S_j . (x0 - j_j), added to the sums,
// written out as Eigen evaluated them.
inline void add_deflected(const DeflectedCluster& k, double x, double y, double z, double& ox, double& oy, double& oz,
                          double& back) {
  const double dx = x - k.joint[0], dy = y - k.joint[1], dz = z - k.joint[2];
  ox += (((k.R[0] * dx + k.R[3] * dy) + k.R[6] * dz) + k.moved[0]) - x;
  oy += (((k.R[1] * dx + k.R[4] * dy) + k.R[7] * dz) + k.moved[1]) - y;
  oz += (((k.R[2] * dx + k.R[5] * dy) + k.R[8] * dz) + k.moved[2]) - z;
  back += ((k.path[0] * dx + k.path[1] * dy) + k.path[2] * dz) + k.lever;
}

}  // namespace

template <typename Real>
void write_static_offsets(const SolverModel<Real>& model, const Attachment<Real>& attachment,
                          const StepScratch<Real>& scratch, StepPrediction<Real>& prediction, size_t begin,
                          size_t end) {
  const TreeModel& tree = model.tree;
  // 4. Per vertex: the mean over its clusters of their deflected poses, as an offset from rest;
  // and the mean of sum_j C_j S_j . (x0 - j_j), the goal's move back per m/s of the vertex when
  // everything moves with it (docs/solver.md, "Aerodynamic damping"). A run of vertices each in
  // one cluster alone (a mean over one, share 1) is one loop on that cluster's pose, vectorised.
  const double* rest = tree.rest_positions.data();
  const uint32_t *offsets = tree.vertex_cluster_offsets.data(), *memberships = tree.vertex_memberships.data();
  const uint32_t* member_cluster = model.member_cluster.data();
  const uint8_t* active = attachment.member_active.data();
  Real *gx = prediction.goal.col(0).data(), *gy = prediction.goal.col(1).data(), *gz = prediction.goal.col(2).data();
  Real* compliance = prediction.damping_compliance.data();
  for (size_t v = begin; v < end;) {
    const size_t run_end = std::min<size_t>(model.vertex_run_end[v], end);
    if (run_end > v) {
      const DeflectedCluster k = deflected_cluster(model, scratch, member_cluster[memberships[offsets[v]]]);
#pragma omp simd
      for (size_t u = v; u < run_end; ++u) {
        double ox = 0, oy = 0, oz = 0, back = 0;
        add_deflected(k, rest[3 * u], rest[3 * u + 1], rest[3 * u + 2], ox, oy, oz, back);
        gx[u] = static_cast<Real>(ox), gy[u] = static_cast<Real>(oy), gz[u] = static_cast<Real>(oz);
        // max(back, 0) rounded, tested after the rounding (a conversion under the test stops
        // GCC's if-conversion): the same value, as back = 0 + term is never -0
        const Real rounded = static_cast<Real>(back);
        compliance[u] = rounded <= Real(0) ? Real(0) : rounded;
      }
      v = run_end;
      continue;
    }
    double ox = 0, oy = 0, oz = 0, back = 0;
    for (uint32_t s = offsets[v]; s < offsets[v + 1]; ++s) {
      const uint32_t slot = memberships[s];
      if (!active[slot]) continue;
      add_deflected(deflected_cluster(model, scratch, member_cluster[slot]), rest[3 * v], rest[3 * v + 1],
                    rest[3 * v + 2], ox, oy, oz, back);
    }
    const double share = double(attachment.vertex_inv_count[v]);
    gx[v] = static_cast<Real>(ox * share), gy[v] = static_cast<Real>(oy * share), gz[v] = static_cast<Real>(oz * share);
    compliance[v] = static_cast<Real>(std::max(back * share, 0.0));
    ++v;
  }
}

#define TREEANIM_BEAM_STATICS(Real)                                                                               \
  template void sum_drag_areas(const SolverModel<Real>&, Attachment<Real>&);                                       \
  template void deflect_bar_chain(const SolverModel<Real>&, const Attachment<Real>&, const SimState&,              \
                                  StepScratch<Real>&);                                                              \
  template void write_static_offsets(const SolverModel<Real>&, const Attachment<Real>&, const StepScratch<Real>&, \
                                     StepPrediction<Real>&, size_t, size_t);
TREEANIM_BEAM_STATICS(float)
TREEANIM_BEAM_STATICS(double)
#undef TREEANIM_BEAM_STATICS

}  // namespace treeanim
