// Shape matching of every awake cluster on the predicted positions (docs/solver.md, "One
// step" 4 and "Local shape matching").
#include "sim/shape_matching.h"

#include <omp.h>

#include <algorithm>
#include <cstddef>
#include <cstring>
#include <string>
#include <type_traits>

#include "common/errors.h"
#include "sim/kernel_isa.h"
#include "sim/lanes.h"
#include "sim/rotation.h"
#include "sim/solver_step.h"

namespace treeanim {

namespace {

// Cluster c's members + predicted displacements u_p (V x 3) => sums[3 i + j] = sum s u_i q_j and
// sums[9 + i] = the centre shift sum (w / sum w) u_i, s = (w / sum w) k (match_in_lanes).
template <typename Real>
void fit_sums(const TreeModel& tree, const Attachment<Real>& a, const Rows3<Real>& predicted_offset, size_t c,
              double (&sums)[12]) {
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
  for (int j = 0; j < 4; ++j) {
    sums[j < 3 ? j : 9] = double(row_x[j]);
    sums[j < 3 ? 3 + j : 10] = double(row_y[j]);
    sums[j < 3 ? 6 + j : 11] = double(row_z[j]);
  }
}

}  // namespace

template <typename Real>
void write_corrections(const SolverModel<Real>& model, const Attachment<Real>& a, const Rows3<Real>& predicted_offset,
                       size_t c, const double (&R)[9], const double (&shift)[3], Rows3<Real>& corrections) {
  const TreeModel& tree = model.tree;
  const Real alpha = static_cast<Real>(model.cluster_alpha[c]);
  const uint32_t* members = tree.cluster_members.data();
  const uint8_t* active = a.member_active.data();
  const Real *qx = a.member_offset.col(0).data(), *qy = a.member_offset.col(1).data(), *qz = a.member_offset.col(2).data();
  const Real *ux = predicted_offset.col(0).data(), *uy = predicted_offset.col(1).data(),
             *uz = predicted_offset.col(2).data();
  Real *cx = corrections.col(0).data(), *cy = corrections.col(1).data(), *cz = corrections.col(2).data();
  const Real r00 = Real(R[0]), r01 = Real(R[3]), r02 = Real(R[6]), r10 = Real(R[1]), r11 = Real(R[4]), r12 = Real(R[7]);
  const Real r20 = Real(R[2]), r21 = Real(R[5]), r22 = Real(R[8]);
  const Real tx = Real(shift[0]), ty = Real(shift[1]), tz = Real(shift[2]);
  // Rest offset q, predicted u, weight => the correction weight (R q - q + shift - u); each a
  // Real, or four members in lanes.
  auto correction = [&](const auto& weight, const auto& x, const auto& y, const auto& z, const auto& vx,
                        const auto& vy, const auto& vz, auto& px, auto& py, auto& pz) {
    px = weight * ((((r00 * x + r01 * y) + r02 * z) - x) + tx - vx);
    py = weight * ((((r10 * x + r11 * y) + r12 * z) - y) + ty - vy);
    pz = weight * ((((r20 * x + r21 * y) + r22 * z) - z) + tz - vz);
  };
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
      correction(weight, x, y, z, vx, vy, vz, cx[s + to_row], cy[s + to_row], cz[s + to_row]);
    }
  };
  const bool released = a.cluster_released[c] != 0;
  const uint32_t begin = tree.cluster_offsets[c];
  if (tree.cluster_offsets[c + 1] - begin == 4 && members[begin + 3] == members[begin] + 3) {
    // A leaf's card: its four members in one vector's lanes, each stored to its row.
    using Lanes = typename Lanes4<Real>::type;
    Lanes x, y, z, vx, vy, vz, weight = Lanes{} + alpha;
    std::memcpy(&x, qx + begin, sizeof x), std::memcpy(&y, qy + begin, sizeof y), std::memcpy(&z, qz + begin, sizeof z);
    const uint32_t v = members[begin];
    std::memcpy(&vx, ux + v, sizeof vx), std::memcpy(&vy, uy + v, sizeof vy), std::memcpy(&vz, uz + v, sizeof vz);
    if (released)
      for (int l = 0; l < 4; ++l) weight[l] = active[begin + l] ? alpha : Real(0);
    Lanes px, py, pz;
    correction(weight, x, y, z, vx, vy, vz, px, py, pz);
    for (int l = 0; l < 4; ++l) {
      const uint32_t row = model.member_correction_row[begin + l];
      cx[row] = px[l], cy[row] = py[l], cz[row] = pz[l];
    }
    return;
  }
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
  double sums[kMatchLanes][12];
  Eigen::Vector3d held[kMatchLanes];
  for (size_t l = 0; l < n; ++l) {
    if (pinned) held[l] = held_point(model, attachment, state, scratch, clusters[l]);
    fit_sums(model.tree, attachment, predicted_offset, clusters[l], sums[l]);
  }
  // Each lane a cluster; lanes without one repeat the first, and what they find is not kept.
  // About the match point o, displaced by w (the centre shift, or the pin):
  // A_pq = (sum s u_p q^T - shift o^T) k + sum s (q - o)(q - o)^T - w (sum s (q - o))^T,
  // each entry in this order (0 about the centre: the shift leaves out the residue of sum s q).
  // Written lane by lane into plain arrays, then loaded as vectors: an element written into a
  // vector goes through memory one at a time.
  double a_lanes[9][kMatchLanes], q_lanes[4][kMatchLanes], point_lanes[3][kMatchLanes], moved_lanes[3][kMatchLanes];
  for (size_t l = 0; l < kMatchLanes; ++l) {
    const size_t from = l < n ? l : 0, c = clusters[from];
    const double* sum = sums[from];
    const double* o = &attachment.cluster_match_point(0, c);
    const double* w = pinned ? held[from].data() : sum + 9;
    const double* rest = &attachment.cluster_rest_moment(0, c);
    const double* offset_sum = &attachment.cluster_offset_sum(0, c);
    const double k = attachment.cluster_match_scale[c];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        a_lanes[i + 3 * j][l] = (((sum[3 * i + j] - sum[9 + i] * o[j]) * k) + rest[i + 3 * j]) - w[i] * offset_sum[j];
    for (int i = 0; i < 3; ++i) point_lanes[i][l] = o[i], moved_lanes[i][l] = w[i];
    for (int i = 0; i < 4; ++i) q_lanes[i][l] = state.cluster_rotations(i, c);
  }
  Double4 A[9], q[4], point[3], moved[3];
  std::memcpy(A, a_lanes, sizeof A);
  std::memcpy(q, q_lanes, sizeof q);
  std::memcpy(point, point_lanes, sizeof point);
  std::memcpy(moved, moved_lanes, sizeof moved);
  extract_rotations(A, q, model.options.rotation_iterations, model.rotation_newton_stop, model.rotation_series_turns);
  Double4 R[9];
  rotation_matrix(q, R);
  // The goal of the match point is o + w: t - t0 = w - (R - I) o (w itself about the centre).
  Double4 shift[3], check = {};
  for (int i = 0; i < 3; ++i) {
    Double4 turned;
    matrix_row_sum(i, R[i] * point[0], R[i + 3] * point[1], R[i + 6] * point[2], turned);
    shift[i] = moved[i] - (turned - point[i]);
    check += shift[i] - shift[i];
  }
  for (int i = 0; i < 9; ++i) check += R[i] - R[i];
  uint32_t bad = kNone;
  for (size_t l = 0; l < n; ++l) {
    const uint32_t c = clusters[l];
    double r[9], t[3];
    for (int i = 0; i < 9; ++i) r[i] = scratch.cluster_rotation_matrix(i, c) = R[i][l];
    for (int i = 0; i < 3; ++i) t[i] = state.cluster_shift(i, c) = shift[i][l];
    for (int i = 0; i < 4; ++i) state.cluster_rotations(i, c) = q[i][l];
    if (check[l] == 0)  // R and the shift finite
      write_corrections(model, attachment, predicted_offset, c, r, t, scratch.member_correction);
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
// their branch's goal for the shared vertex (hierarchical: a 1 g leaf's fit cannot pull its
// branch, nor the leaf drift off it in a gale; its drag reaches the branch through the chain). Sampling the next step's air here, per cluster, saves a
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
    AirLanes<Real> leaves_air(model, attachment, state, scratch);
    with_kernel_isa([&] {
      for (size_t c = first; c < last; ++c) {
        if (!cluster_awake(model, attachment, state, c)) continue;
        if (attachment.cluster_pin_slot[c] == kNone)
          branches.add(static_cast<uint32_t>(c));
        else
          leaves_air.add(static_cast<uint32_t>(c));  // the leaf is matched after its branch, its air now
      }
      branches.flush();
      leaves_air.flush();
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
                                  const double(&)[9], const double(&)[3], Rows3<Real>&);                           \
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
