// Shape matching of every awake cluster on the predicted positions (docs/solver.md, "One
// step" 2 and "Local shape matching").
#include "sim/shape_matching.h"

#include <omp.h>

#include <algorithm>
#include <cstddef>
#include <string>
#include <type_traits>

#include "common/errors.h"
#include "sim/kernel_isa.h"
#include "sim/lanes.h"
#include "sim/rotation.h"
#include "sim/solver_step.h"

namespace treeanim {

namespace {

// Cluster c's rest data + predicted displacements u_p (V x 3); pinned_point: the displacement
// from rest of the match point o where that point is held (an attached leaf), nullptr where o
// is the centre and follows the members => A, its A_pq about o, normalised, whose rotation
// (extract_rotation) is the fit's, and w, the displacement of o.
template <typename Real>
void fit_matrix(const TreeModel& tree, const Attachment<Real>& a, const Rows3<Real>& predicted_offset, size_t c,
                const Eigen::Vector3d* pinned_point, Eigen::Matrix3d& A, Eigen::Vector3d& point_shift) {
  const uint32_t begin = tree.cluster_offsets[c], end = tree.cluster_offsets[c + 1];
  // Cluster-local coordinates: d = p - t0 = u_p + q (x0 - t0 = q for a member), small
  // numbers wherever the tree stands and however far it travelled. With the rest terms
  // precomputed, one pass over the displacements sums the centre shift
  // t - t0 = sum (w / sum w) u_p and sum s u_p q^T, s = (w / sum w) k with the cluster's
  // match scale k. About the match point o, displaced by w (the centre shift, or the pin):
  // A_pq = sum s (d - o - w)(q - o)^T = sum s u_p q^T - k shift o^T + sum s (q - o)(q - o)^T
  //        - w (sum s (q - o))^T,
  // the third term precomputed. About the centre, sum s q is 0 but for the round-off of the
  // stored q; the shift leaves that residue out, so at the rest pose (u_p = 0) the shift is
  // exactly 0 and A_pq is the exactly symmetric rest moment: no goal pulls a resting tree.
  // One weight per member serves both sums; they run in Real, with the round-off of the
  // values they sum. q is read here and again by write_corrections, while it is in cache.
  // The twelve sums as three rows of four lanes (lanes.h): {a_i0, a_i1, a_i2, s_i} += u_i {w, share},
  // each lane the scalar sum a_ij += u_i w_j, s_i += share u_i (w_j = share q_j; a product
  // is the same either way round).
  using Lanes = typename Lanes4<Real>::type;
  Lanes row_x = {0, 0, 0, 0}, row_y = {0, 0, 0, 0}, row_z = {0, 0, 0, 0};
  const Real *ux = predicted_offset.col(0).data(), *uy = predicted_offset.col(1).data(),
             *uz = predicted_offset.col(2).data();
  const Real *qx = a.member_offset.col(0).data(), *qy = a.member_offset.col(1).data(), *qz = a.member_offset.col(2).data();
  for (uint32_t s = begin; s < end; ++s) {
    const uint32_t v = tree.cluster_members[s];
    const Real x = ux[v], y = uy[v], z = uz[v];
    const Real share = a.member_centre_weight[s];
    const Lanes w = Lanes{qx[s], qy[s], qz[s], 1} * share;
    row_x += x * w, row_y += y * w, row_z += z * w;
  }
  const Real a00 = row_x[0], a01 = row_x[1], a02 = row_x[2], a10 = row_y[0], a11 = row_y[1], a12 = row_y[2];
  const Real a20 = row_z[0], a21 = row_z[1], a22 = row_z[2];
  const Eigen::Vector3d centre_shift(row_x[3], row_y[3], row_z[3]);
  const Eigen::Vector3d point = a.cluster_match_point.col(c);
  point_shift = pinned_point ? *pinned_point : centre_shift;
  A << double(a00), double(a01), double(a02), double(a10), double(a11), double(a12), double(a20), double(a21), double(a22);
  A -= centre_shift * point.transpose();  // 0 about the centre
  A *= a.cluster_match_scale[c];
  A += Eigen::Map<const Eigen::Matrix3d>(&a.cluster_rest_moment(0, c));
  A -= point_shift * a.cluster_offset_sum.col(c).transpose();
}

}  // namespace

template <typename Real>
void write_corrections(const SolverModel<Real>& model, const Attachment<Real>& a, const Rows3<Real>& predicted_offset,
                       size_t c, const Eigen::Matrix3d& R, const Eigen::Vector3d& shift, Rows3<Real>& corrections) {
  const TreeModel& tree = model.tree;
  const Real alpha = static_cast<Real>(model.cluster_alpha[c]);
  const uint32_t* members = tree.cluster_members.data();
  const uint8_t* active = a.member_active.data();
  const Real *qx = a.member_offset.col(0).data(), *qy = a.member_offset.col(1).data(), *qz = a.member_offset.col(2).data();
  const Real *ux = predicted_offset.col(0).data(), *uy = predicted_offset.col(1).data(),
             *uz = predicted_offset.col(2).data();
  Real *cx = corrections.col(0).data(), *cy = corrections.col(1).data(), *cz = corrections.col(2).data();
  const Eigen::Matrix<Real, 3, 3> r = R.template cast<Real>();
  const Eigen::Matrix<Real, 3, 1> t = shift.template cast<Real>();
  const Real r00 = r(0, 0), r01 = r(0, 1), r02 = r(0, 2), r10 = r(1, 0), r11 = r(1, 1), r12 = r(1, 2);
  const Real r20 = r(2, 0), r21 = r(2, 1), r22 = r(2, 2), tx = t.x(), ty = t.y(), tz = t.z();
  // A run of memberships whose rows are consecutive is one loop; where the rows are the member
  // vertices' own (a free vertex in this cluster alone), their u is read in order too. Only a
  // cluster with released memberships reads their flags (Attachment::cluster_released).
  auto correct = [&](const CorrectionRun& run, auto own_rows, auto any_released) {
    const ptrdiff_t to_row = ptrdiff_t(run.row) - ptrdiff_t(run.begin);
#pragma omp simd
    for (uint32_t s = run.begin; s < run.end; ++s) {
      const Real x = qx[s], y = qy[s], z = qz[s];
      Real vx, vy, vz;
      if constexpr (own_rows) {
        vx = ux[s + to_row], vy = uy[s + to_row], vz = uz[s + to_row];
      } else {
        const uint32_t v = members[s];
        vx = ux[v], vy = uy[v], vz = uz[v];
      }
      Real weight = alpha;
      if constexpr (any_released) weight = active[s] ? alpha : Real(0);  // a released membership pulls nothing
      cx[s + to_row] = weight * ((((r00 * x + r01 * y) + r02 * z) - x) + tx - vx);
      cy[s + to_row] = weight * ((((r10 * x + r11 * y) + r12 * z) - y) + ty - vy);
      cz[s + to_row] = weight * ((((r20 * x + r21 * y) + r22 * z) - z) + tz - vz);
    }
  };
  const bool released = a.cluster_released[c] != 0;
  for (uint32_t i = model.correction_run_offsets[c]; i < model.correction_run_offsets[c + 1]; ++i) {
    const CorrectionRun& run = model.correction_runs[i];
    const bool own = run.row < model.V;
    if (!released)
      own ? correct(run, std::true_type{}, std::false_type{}) : correct(run, std::false_type{}, std::false_type{});
    else
      own ? correct(run, std::true_type{}, std::true_type{}) : correct(run, std::false_type{}, std::true_type{});
  }
}

template <typename Real>
uint32_t match_in_lanes(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state,
                        StepScratch<Real>& scratch, std::span<const uint32_t> clusters, bool pinned) {
  const Rows3<Real>& predicted_offset = state.prediction<Real>().offset;
  const size_t n = clusters.size();
  Eigen::Matrix3d A[kMatchLanes];
  Eigen::Vector3d point_shift[kMatchLanes], held[kMatchLanes];
  for (size_t l = 0; l < n; ++l) {
    if (pinned) held[l] = held_point(model, attachment, state, scratch, clusters[l]);
    fit_matrix(model.tree, attachment, predicted_offset, clusters[l], pinned ? &held[l] : nullptr, A[l],
               point_shift[l]);
  }
  // Lanes without a cluster repeat the first; what they find is not kept.
  Double4 a[9], q[4];
  for (size_t l = 0; l < kMatchLanes; ++l) {
    const size_t from = l < n ? l : 0;
    for (int i = 0; i < 9; ++i) a[i][l] = A[from](i);
    for (int k = 0; k < 4; ++k) q[k][l] = state.cluster_rotations(k, clusters[from]);
  }
  extract_rotations(a, q, model.options.rotation_iterations, model.rotation_newton_stop);
  uint32_t bad = kNone;
  for (size_t l = 0; l < n; ++l) {
    const uint32_t c = clusters[l];
    const Eigen::Quaterniond rotation(q[3][l], q[0][l], q[1][l], q[2][l]);
    const Eigen::Matrix3d R = rotation.toRotationMatrix();
    const Eigen::Vector3d point = attachment.cluster_match_point.col(c);
    // The goal of the match point is o + w: t - t0 = w - (R - I) o (w itself about the centre).
    const Eigen::Vector3d shift = point_shift[l] - (R * point - point);
    state.cluster_rotations.col(c) = rotation.coeffs();
    state.cluster_shift.col(c) = shift;
    Eigen::Map<Eigen::Matrix3d>(&scratch.cluster_rotation_matrix(0, c)) = R;
    if (R.allFinite() && shift.allFinite())
      write_corrections(model, attachment, predicted_offset, c, R, shift, scratch.member_correction);
    else
      bad = std::min(bad, c);
  }
  return bad;
}

template <typename Real>
uint32_t match_listed_clusters(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state,
                               StepScratch<Real>& scratch, std::span<const uint32_t> clusters) {
  MatchLanes<Real> branches(model, attachment, state, scratch, false, true);
  MatchLanes<Real> leaves(model, attachment, state, scratch, true, true);
  with_kernel_isa([&] {
    for (const uint32_t c : clusters) {
      if (!cluster_awake(model, attachment, state, c)) continue;
      if (attachment.cluster_pin_slot[c] == kNone) {
        branches.add(c);
      } else {
        branches.flush();  // a leaf's branch is listed before it
        leaves.add(c);
      }
    }
    branches.flush();
    leaves.flush();
  });
  return std::min(branches.bad(), leaves.bad());
}

// Branches and free leaves first, then the attached leaves, whose translation is pinned to
// their branch's goal for the shared vertex (hierarchical: a 1 g leaf cannot drag its branch,
// nor drift off it in a gale). Sampling the next step's air here, per cluster, saves a
// parallel region per step.
template <typename Real>
void match_clusters(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state,
                    StepScratch<Real>& scratch, long long frame, int substep) {
  uint32_t bad = kNone;
#pragma omp parallel if (model.parallel) reduction(min : bad)
  {
    // Named, not a structured binding: the lambda below captures them (clang before 16 cannot).
    const std::pair<size_t, size_t> range =
        balanced_range(model.match_work_offsets, omp_get_thread_num(), omp_get_num_threads());
    const size_t first = range.first, last = range.second;
    MatchLanes<Real> branches(model, attachment, state, scratch, false, true);
    with_kernel_isa([&] {
      for (size_t c = first; c < last; ++c) {
        if (!cluster_awake(model, attachment, state, c)) continue;
        if (attachment.cluster_pin_slot[c] == kNone)
          branches.add(static_cast<uint32_t>(c));
        else
          sample_cluster_air(model, attachment, state, scratch, c);  // the leaf is matched after its branch
      }
      branches.flush();
    });
    bad = std::min(bad, branches.bad());
    if (!model.pinned_leaf_clusters.empty()) {
#pragma omp barrier
      match_attached_leaves(model, attachment, state, scratch, bad);
    }
  }
  if (bad != kNone) throw_match_failure(frame, substep, bad);
}

void throw_match_failure(long long frame, int substep, uint32_t cluster) {
  throw SimulationError("frame " + std::to_string(frame) + ", substep " + std::to_string(substep) + ", cluster " +
                        std::to_string(cluster) + ": the shape match produced a non-finite rotation or centre");
}

#define TREEANIM_SHAPE_MATCHING(Real)                                                                              \
  template void write_corrections(const SolverModel<Real>&, const Attachment<Real>&, const Rows3<Real>&, size_t,   \
                                  const Eigen::Matrix3d&, const Eigen::Vector3d&, Rows3<Real>&);                   \
  template uint32_t match_in_lanes(const SolverModel<Real>&, const Attachment<Real>&, SimState&, StepScratch<Real>&, \
                                   std::span<const uint32_t>, bool);                                               \
  template void match_clusters(const SolverModel<Real>&, const Attachment<Real>&, SimState&, StepScratch<Real>&,   \
                               long long, int);                                                                    \
  template uint32_t match_listed_clusters(const SolverModel<Real>&, const Attachment<Real>&, SimState&,            \
                                          StepScratch<Real>&, std::span<const uint32_t>);
TREEANIM_SHAPE_MATCHING(float)
TREEANIM_SHAPE_MATCHING(double)
#undef TREEANIM_SHAPE_MATCHING

}  // namespace treeanim
