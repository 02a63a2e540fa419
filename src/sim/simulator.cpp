#include "sim/simulator.h"

#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <string>

#include "common/errors.h"
#include "sim/rotation.h"
#include "sim/stiffness.h"
#include "sim/wind.h"

namespace treeanim {

namespace {

constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();
constexpr int kMaxModes = 64;  // read_wind_options caps turbulence_modes here

// CSR offsets (n+1) + this thread's index and the thread count => the contiguous range of
// rows [begin, end) holding an equal share of the entries. Balances clusters of very
// different sizes (trunk rings, 4-vertex leaves); results never depend on the split.
std::pair<size_t, size_t> balanced_range(const std::vector<uint32_t>& offsets, int thread, int threads) {
  const size_t n = offsets.size() - 1;
  const double total = offsets.back();
  auto row_at = [&](int t) {
    if (t == 0) return size_t(0);
    if (t == threads) return n;
    const double target = total * t / threads;
    return size_t(std::lower_bound(offsets.begin(), offsets.end(), target) - offsets.begin());
  };
  return {std::min(row_at(thread), n), std::min(row_at(thread + 1), n)};
}

// Union-find root with path halving.
uint32_t find_root(std::vector<uint32_t>& parent, uint32_t a) {
  while (parent[a] != a) a = parent[a] = parent[parent[a]];
  return a;
}

// One block of a thread's vertices in vertex_pass, on its stack (no allocation).
constexpr int kVertexBlock = 256;
// 0, 1, ..., kVertexBlock - 1: a block's own lanes as rows.
const std::array<uint32_t, kVertexBlock> kLaneIndex = [] {
  std::array<uint32_t, kVertexBlock> lanes{};
  for (int k = 0; k < kVertexBlock; ++k) lanes[k] = static_cast<uint32_t>(k);
  return lanes;
}();
// Where predict_block reads a block's vertices: the mean correction of vertex k is row
// pull_row[k] of `pull`; the factors are per vertex.
template <typename Real>
struct VertexInputs {
  const Real* pull[3];
  const uint32_t* pull_row;
  const Real *drag, *damping, *global;
  const uint8_t* flying;
};

template <typename Real>
struct VertexBlock {
  uint8_t moving[kVertexBlock];            // 1: the vertex steps; 0: anchored, asleep, no cluster
  Real pull[3][kVertexBlock];              // m, mean correction of its clusters, per axis
  // Per-step factors of each vertex; a vertex that does not move gets those of a still
  // point (damping 1, no drag, no pull, no fall), which map its u = 0, v = 0 onto themselves
  // exactly, so that the loop needs no branch.
  Real drag[kVertexBlock];                 // 1/m, drag acceleration per (m/s)^2
  Real damping[kVertexBlock];              // velocity factor
  Real global[kVertexBlock];               // global rate per step
  uint8_t flying[kVertexBlock];            // 1 on a flying leaf
  Real end_offset[3][kVertexBlock];        // m, corrected u at the end of a frame (kEnd)
  Real end_velocity[3][kVertexBlock];      // m/s, corrected v at the end of a frame (kEnd)
  Real check[kVertexBlock];                // sum of the new values: finite iff all are
  Real excess[kVertexBlock];               // m^2, > 0: ran farther than the runaway limit
};

}  // namespace

// What the Simulator forwards to: the solver in the precision the options ask for.
struct Simulator::Impl {
  virtual ~Impl() = default;
  virtual SimState initial_state(double time) const = 0;
  virtual void advance_frame(SimState& state, long long frame) = 0;
};

namespace {

// The solver, its step state stored in `Real` (docs/solver.md, "Precision"): rest offsets,
// predicted offsets, velocities, corrections and per-vertex factors, the arrays every step
// streams through, and the fit's sums over them. A_pq once assembled, the rest moments, the
// rotation, the cluster centres and shifts, the rates and the state handed out stay double.
template <typename Real>
struct Solver final : Simulator::Impl {
  using Rows3 = Eigen::Matrix<Real, Eigen::Dynamic, 3>;  // (n x 3), a column per axis
  using Vector3 = Eigen::Matrix<Real, 3, 1>;
  using Inputs = VertexInputs<Real>;
  using Block = VertexBlock<Real>;
  const TreeModel& model;
  SimOptions options;
  WindField wind;
  double frame_dt;
  int substeps;
  double h;  // s, one substep
  // m^2: (2 x the largest extent of the rest mesh)^2. An attached vertex of an anchored tree
  // farther than that from rest means the tree came apart (a step the stiffness cannot
  // resolve): the bake stops rather than writing it. Infinite without anchors (a free body
  // may travel) and for a single-point model.
  double runaway_distance2;
  size_t V, C, M, L;

  // --- per membership (M), in cluster_members order ---
  // Arrays of 3-vectors read or written in the step are (n x 3): a column per axis
  // (structure of arrays), so that the vertex pass and the goal writes run on SIMD packets.
  std::vector<uint32_t> member_cluster;    // (M) cluster of the membership
  Rows3 member_offset;                     // (M x 3) m, rest offset q = x0 - t0 from the cluster's rest centre
  // (M) w / sum(w): mass share in the cluster's centre; times cluster_match_scale, the weight
  // of the member in A_pq
  std::vector<Real> member_centre_weight;
  std::vector<uint8_t> member_active;      // (M) 0 once the membership was released (detached leaf)
  // (M) 1 where the member's mass counts in its cluster's fit: active, and not an attached
  // leaf's shared vertex in its branch (see precompute_pins)
  std::vector<uint8_t> member_in_fit;
  // ((M + 1) x 3) m, alpha_c (g - p) of the current step; row M stays 0 (the pull of an
  // anchor). Before the vertex prediction, the first membership's row of a shared vertex
  // takes the vertex's mean correction (average_shared_pulls).
  Rows3 member_correction;

  // --- per cluster (C) ---
  Eigen::Matrix3Xd cluster_rest_centre;    // (3 x C) m, mass-weighted rest centre t0
  // (3 x C) m, rest position minus t0 of the point the fit rotates about, o: 0 (the centre)
  // but for an attached leaf, which turns about its shared vertex (see match_clusters)
  Eigen::Matrix3Xd cluster_match_point;
  // (C) 1/m^2, 1 / sum((w / sum w) |q - o|^2): A_pq = sum s d (q - o)^T with s = (w / sum w)
  // times it is of order 1 for any cluster size
  std::vector<double> cluster_match_scale;
  Eigen::Matrix3Xd cluster_offset_sum;     // (3 x C) 1/m, sum of s (q - o) over the members (o = 0: round-off only)
  Eigen::Matrix<double, 9, Eigen::Dynamic> cluster_rest_moment;  // (9 x C) sum s (q - o)(q - o)^T, column-major: A_pq at rest
  std::vector<double> cluster_alpha;       // (C) local rate per step
  std::vector<uint32_t> cluster_island;    // (C) island id
  std::vector<uint8_t> cluster_flying;     // (C) 1: a detached leaf (always awake)
  std::vector<double> cluster_turbulence_sin, cluster_turbulence_cos;  // (C x N) spatial phases at t0
  Rows3 cluster_air;                       // (C x 3) m/s, air velocity at the cluster this step
  Eigen::Matrix3Xd cluster_shift;          // (3 x C) m, t - t0: the centre of the last fit from the rest centre
  Eigen::Matrix<double, 9, Eigen::Dynamic> cluster_rotation_matrix;  // (9 x C) R of the last fit, column-major
  std::vector<uint32_t> cluster_pin_slot;  // (C) attached leaf: membership of its shared vertex in the branch; else kNone
  std::vector<uint32_t> cluster_pin_own_slot;  // (C) attached leaf: membership of the shared vertex in the leaf
  std::vector<uint32_t> pinned_leaf_clusters;  // clusters of the leaves that start attached to a branch

  // --- per vertex (V) ---
  std::vector<Real> vertex_global;         // (V) global rate per step (0: off, anchored, flying)
  std::vector<Real> vertex_damping;        // (V) velocity factor per step
  std::vector<Real> vertex_drag;           // (V) 1/m, 0.5 rho Cd A / m: drag acceleration per (m/s)^2
  std::vector<Real> vertex_inv_count;      // (V) 1 / number of active memberships (0: none)
  std::vector<uint32_t> vertex_air_cluster;// (V) the cluster whose air velocity the vertex feels
  std::vector<uint32_t> vertex_pull_row;   // (V) row of member_correction with its mean correction (M: anchored)
  std::vector<uint32_t> shared_vertices;   // free vertices in two or more clusters, ascending
  std::vector<uint8_t> vertex_flying;      // (V) 1: on a detached leaf (gravity on, global off)
  std::vector<uint32_t> vertex_island;     // (V) island id, kNone for anchored vertices
  Rows3 vertex_drag_force;                 // (V x 3) N, drag of the last step; only with detachment
  // (V x 3) m, u = p - x0: the predicted position p = x + h v* of the current step as a
  // displacement from rest. Small numbers wherever the tree stands, and x0 is not read
  // again until the frame ends.
  Rows3 predicted_offset;
  // (V x 3) m/s, v* of the current step; the state holds v at the end of a frame. After
  // the last step it holds v* of the next frame's first step (see frame()).
  Rows3 step_velocity;

  // --- islands (I): clusters connected through shared non-anchored vertices ---
  size_t I = 0;
  std::vector<uint32_t> island_vertex_offsets;  // (I+1) CSR into island_vertices
  std::vector<uint32_t> island_vertices;        // non-anchored vertices, ascending per island

  std::vector<uint8_t> island_fell_asleep; // (I) scratch of check_sleep

  // --- the next frame's first prediction, made by the last step of a frame ---
  uint64_t carried_stamp = 0;              // the SimState::prediction_stamp it belongs to; 0: none
  uint64_t stamps_issued = 0;

  // --- leaves ---
  std::vector<uint8_t> applied_attached;  // (L) detachments already applied to the arrays above
  bool detach_enabled;
  // Threads only pay off above a few thousand memberships; below, the fork/join costs more
  // than the work (results are identical either way).
  bool parallel;

  // --- per-step scratch (no allocation in the step): the wind at the time being sampled ---
  Eigen::Vector3d air_base = Eigen::Vector3d::Zero();  // m/s, mean wind + gust
  double air_scale = 0;                                // m/s, turbulence amplitude
  double turbulence_sin_b[kMaxModes], turbulence_cos_b[kMaxModes];

  Solver(const TreeModel& m, const SimOptions& o, const WindOptions& w, double dt, int n);
  SimState initial_state(double time) const override;
  void advance_frame(SimState& state, long long frame) override;
  void precompute_members();
  void rebuild_cluster_rest(uint32_t c);
  void precompute_drag(const WindOptions& w);
  void precompute_islands();
  void detach_leaf(SimState& state, size_t leaf);
  bool sync_detachments(SimState& state);
  void frame(SimState& state, long long frame_index);
  void set_air_time(double t);
  void sample_cluster_air(size_t c);
  bool all_resting(const SimState& state) const;
  void sample_air(const SimState& state);
  enum class Pass { kStart, kStep, kEnd };
  bool vertex_pass(SimState& state, Pass pass, long long frame, int substep);
  void gather_block(const SimState& state, Pass pass, bool any_asleep, size_t begin, int n, Block& block);
  template <bool kEnd, bool kDetach>
  bool predict_block(size_t begin, int n, const Inputs& in, Block& block);
  void average_shared_pulls(size_t first, size_t last);
  // Vertex v => the mean of its clusters' corrections, summed in membership order (never the
  // sum: Eq. 7 with overlaps). Defined here so that it inlines into the vertex pass.
  Eigen::Matrix<Real, 1, 3> mean_correction(uint32_t v) const {
    Eigen::Matrix<Real, 1, 3> pull = Eigen::Matrix<Real, 1, 3>::Zero();
    for (uint32_t s = model.vertex_cluster_offsets[v]; s < model.vertex_cluster_offsets[v + 1]; ++s)
      pull += member_correction.row(model.vertex_memberships[s]);
    return pull * vertex_inv_count[v];
  }
  bool fit_cluster(SimState& state, size_t c, const Eigen::Vector3d* pinned_point, Eigen::Matrix3d& R,
                   Eigen::Vector3d& shift);
  void write_corrections(size_t c, const Eigen::Matrix3d& R, const Eigen::Vector3d& shift);
  void match_clusters(SimState& state, long long frame, int substep);
  void precompute_pins();
  void check_detachments(SimState& state);
  bool check_sleep(SimState& state, double t);
  bool cluster_awake(const SimState& state, size_t c) const {
    return cluster_flying[c] || !state.island_asleep[cluster_island[c]];
  }
};

template <typename Real>
Solver<Real>::Solver(const TreeModel& m, const SimOptions& o, const WindOptions& w, double dt, int n)
    : model(m), options(o), wind(w), frame_dt(dt), substeps(n), h(dt / n),
      V(m.vertex_count()), C(m.cluster_count()), M(m.membership_count()), L(m.leaf_count()),
      detach_enabled(o.leaf_detach_force > 0 && m.leaf_count() > 0),
      parallel(m.membership_count() >= 4096) {
  if (!(dt > 0) || n < 1) throw InputError("simulator: frame_dt must be > 0 and substeps >= 1");
  const double size = V ? (m.rest_positions.rowwise().maxCoeff() - m.rest_positions.rowwise().minCoeff()).maxCoeff() : 0.0;
  const bool anchored = std::any_of(m.vertex_anchored.begin(), m.vertex_anchored.end(), [](auto a) { return a != 0; });
  runaway_distance2 = anchored && size > 0 ? 4 * size * size : std::numeric_limits<double>::infinity();
  precompute_members();
  precompute_pins();
  for (size_t c = 0; c < C; ++c) rebuild_cluster_rest(static_cast<uint32_t>(c));
  const StepRates rates = compute_step_rates(model, options, h);
  cluster_alpha = rates.cluster_alpha;
  vertex_global.assign(rates.vertex_global.begin(), rates.vertex_global.end());
  vertex_damping.assign(rates.vertex_damping.begin(), rates.vertex_damping.end());
  precompute_drag(w);
  precompute_islands();
  island_fell_asleep.assign(I, 0);
  cluster_air.setZero(C, 3);
  cluster_shift.setZero(3, C);
  cluster_rotation_matrix.setZero(9, C);
  predicted_offset.setZero(V, 3);
  step_velocity.setZero(V, 3);
  cluster_flying.assign(C, 0);
  vertex_flying.assign(V, 0);
  applied_attached.assign(L, 1);
  if (detach_enabled) vertex_drag_force.setZero(V, 3);
  // Spatial turbulence phases at the rest centres: the tree moves little against the
  // length scale of the eddies, so they are evaluated once (flying leaves use their centre).
  const int N = wind.mode_count();
  cluster_turbulence_sin.resize(C * N);
  cluster_turbulence_cos.resize(C * N);
  for (size_t c = 0; c < C; ++c)
    wind.spatial_phases(cluster_rest_centre.col(c), &cluster_turbulence_sin[c * N], &cluster_turbulence_cos[c * N]);
}

// Model CSR => per-membership cluster ids and state, per-vertex counts and correction rows
// (the rest data comes from rebuild_cluster_rest, once the pins are known).
template <typename Real>
void Solver<Real>::precompute_members() {
  member_cluster.resize(M);
  for (size_t c = 0; c < C; ++c)
    for (uint32_t s = model.cluster_offsets[c]; s < model.cluster_offsets[c + 1]; ++s)
      member_cluster[s] = static_cast<uint32_t>(c);
  member_offset.setZero(M, 3);
  member_centre_weight.assign(M, 0);
  member_active.assign(M, 1);
  member_in_fit.assign(M, 1);
  member_correction.setZero(M + 1, 3);
  cluster_rest_centre.setZero(3, C);
  cluster_match_point.setZero(3, C);
  cluster_match_scale.assign(C, 0);
  cluster_offset_sum.setZero(3, C);
  cluster_rest_moment.setZero(9, C);
  vertex_inv_count.assign(V, 0);
  vertex_air_cluster.assign(V, 0);
  vertex_pull_row.assign(V, static_cast<uint32_t>(M));
  for (size_t v = 0; v < V; ++v) {
    const uint32_t begin = model.vertex_cluster_offsets[v], end = model.vertex_cluster_offsets[v + 1];
    vertex_inv_count[v] = end > begin ? Real(1) / Real(end - begin) : Real(0);
    vertex_air_cluster[v] = end > begin ? member_cluster[model.vertex_memberships[begin]] : 0;
    if (model.vertex_anchored[v] || end == begin) continue;
    vertex_pull_row[v] = model.vertex_memberships[begin];
    if (end - begin > 1) shared_vertices.push_back(static_cast<uint32_t>(v));
  }
}

// Active members of cluster c => its rest centre, rest offsets and normalised weights, and
// the rest moment about its match point (an attached leaf's shared vertex, else the centre).
// Weights are vertex masses; a cluster without mass (all members anchored or massless)
// falls back to equal weights, so its shape is still defined.
template <typename Real>
void Solver<Real>::rebuild_cluster_rest(uint32_t c) {
  const uint32_t begin = model.cluster_offsets[c], end = model.cluster_offsets[c + 1];
  double total = 0;
  for (uint32_t s = begin; s < end; ++s)
    if (member_in_fit[s]) total += model.vertex_mass[model.cluster_members[s]];
  const bool uniform = !(total > 0);
  auto weight = [&](uint32_t s) {
    return !member_in_fit[s] ? 0.0 : uniform ? 1.0 : model.vertex_mass[model.cluster_members[s]];
  };
  if (uniform) total = 0;
  if (uniform)
    for (uint32_t s = begin; s < end; ++s) total += weight(s);
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (uint32_t s = begin; s < end; ++s)
    centre += (weight(s) / total) * model.rest_positions.col(model.cluster_members[s]);
  cluster_rest_centre.col(c) = centre;
  for (uint32_t s = begin; s < end; ++s) {
    const Eigen::Vector3d exact = member_active[s] ? Eigen::Vector3d(model.rest_positions.col(model.cluster_members[s]) - centre)
                                                   : Eigen::Vector3d::Zero();
    member_offset.row(s) = exact.transpose().template cast<Real>();
    member_centre_weight[s] = static_cast<Real>(total > 0 ? weight(s) / total : 0.0);
  }
  const Eigen::Vector3d point = cluster_pin_slot[c] == kNone
                                    ? Eigen::Vector3d::Zero()
                                    : Eigen::Vector3d(member_offset.row(cluster_pin_own_slot[c]).transpose().template cast<double>());
  cluster_match_point.col(c) = point;
  // The sums below are taken over the stored (Real) q and weights, the values the step reads.
  double spread = 0;  // sum (w / sum w) |q - o|^2, m^2
  Eigen::Vector3d offset_sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d moment = Eigen::Matrix3d::Zero();
  for (uint32_t s = begin; s < end; ++s) {
    const double share = member_centre_weight[s];
    const Eigen::Vector3d q = member_offset.row(s).transpose().template cast<double>() - point;
    spread += share * q.squaredNorm();
    offset_sum += share * q;
    // Each entry as w (q_i q_j): exactly symmetric, so R = I exactly at the rest pose.
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) moment(i, j) += share * (q[i] * q[j]);
  }
  // A single-point cluster has no shape: its A_pq is 0 and the rotation keeps its warm start.
  const double scale = spread > 0 ? 1.0 / spread : 0.0;
  cluster_match_scale[c] = scale;
  moment *= scale;
  cluster_offset_sum.col(c) = scale * offset_sum;
  Eigen::Map<Eigen::Matrix3d>(&cluster_rest_moment(0, c)) = moment;
}

// Drag areas and coefficients => per-vertex drag constants.
template <typename Real>
void Solver<Real>::precompute_drag(const WindOptions& w) {
  vertex_drag.assign(V, 0);
  for (size_t v = 0; v < V; ++v) {
    const double mass = model.vertex_mass[v];
    if (model.vertex_anchored[v] || !(mass > 0)) continue;
    const double cd = model.vertex_leaf[v] >= 0 ? w.leaf_drag_coefficient : w.branch_drag_coefficient;
    vertex_drag[v] = static_cast<Real>(0.5 * w.air_density * cd * model.vertex_drag_area[v] / mass);
  }
}

// Clusters sharing a non-anchored vertex => one island (anchors hold, they do not couple).
template <typename Real>
void Solver<Real>::precompute_islands() {
  std::vector<uint32_t> parent(C);
  std::iota(parent.begin(), parent.end(), 0u);
  for (size_t v = 0; v < V; ++v) {
    if (model.vertex_anchored[v]) continue;
    const uint32_t begin = model.vertex_cluster_offsets[v], end = model.vertex_cluster_offsets[v + 1];
    for (uint32_t s = begin + 1; s < end; ++s) {
      const uint32_t a = find_root(parent, member_cluster[model.vertex_memberships[begin]]);
      const uint32_t b = find_root(parent, member_cluster[model.vertex_memberships[s]]);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  }
  std::vector<uint32_t> id_of_root(C, kNone);
  cluster_island.resize(C);
  I = 0;
  for (size_t c = 0; c < C; ++c) {
    const uint32_t r = find_root(parent, static_cast<uint32_t>(c));
    if (id_of_root[r] == kNone) id_of_root[r] = static_cast<uint32_t>(I++);
    cluster_island[c] = id_of_root[r];
  }
  vertex_island.assign(V, kNone);
  island_vertex_offsets.assign(I + 1, 0);
  for (size_t v = 0; v < V; ++v) {
    const uint32_t begin = model.vertex_cluster_offsets[v];
    if (model.vertex_anchored[v] || begin == model.vertex_cluster_offsets[v + 1]) continue;
    vertex_island[v] = cluster_island[member_cluster[model.vertex_memberships[begin]]];
    ++island_vertex_offsets[vertex_island[v] + 1];
  }
  for (size_t i = 0; i < I; ++i) island_vertex_offsets[i + 1] += island_vertex_offsets[i];
  island_vertices.resize(island_vertex_offsets[I]);
  std::vector<uint32_t> fill(island_vertex_offsets.begin(), island_vertex_offsets.end() - 1);
  for (size_t v = 0; v < V; ++v)
    if (vertex_island[v] != kNone) island_vertices[fill[vertex_island[v]]++] = static_cast<uint32_t>(v);
}

// Leaves => the membership slots that pin each attached leaf to its branch (see match_clusters).
// A leaf whose shared vertex is in no other cluster is matched like a branch. The shared
// vertex, where it is the leaf's own, does not count in its branch's fit: it carries leaf
// mass and leaf drag, and a leaf does not load its branch (docs/solver.md, "Leaves"). Counted,
// its lag behind its goal (held by the leaf at rate 1, by the branch at alpha_b) let a
// share alpha_b of its drag through, so the branch's rest shape in a steady wind changed with
// the step as (omega_b h)^2.
template <typename Real>
void Solver<Real>::precompute_pins() {
  cluster_pin_slot.assign(C, kNone);
  cluster_pin_own_slot.assign(C, kNone);
  for (size_t l = 0; l < L; ++l) {
    const uint32_t c = model.leaf_cluster[l], a = model.leaf_attachment_vertex[l];
    uint32_t own = kNone, pin = kNone;
    for (uint32_t s = model.vertex_cluster_offsets[a]; s < model.vertex_cluster_offsets[a + 1]; ++s) {
      const uint32_t slot = model.vertex_memberships[s];
      if (member_cluster[slot] == c) own = slot;
      else if (pin == kNone && model.cluster_kind[member_cluster[slot]] == kClusterBranch) pin = slot;
    }
    if (own == kNone || pin == kNone) continue;
    cluster_pin_slot[c] = pin;
    cluster_pin_own_slot[c] = own;
    pinned_leaf_clusters.push_back(c);
    if (model.vertex_leaf[a] == static_cast<int32_t>(l)) member_in_fit[pin] = 0;
  }
}

// Releases leaf `leaf` from its branch (paper 4.2): the shared vertex stays with the side it
// was built for (a leaf vertex leaves its branch clusters; a branch vertex leaves the leaf),
// the clusters that lost a member get new rest data, and the leaf's vertices fly.
template <typename Real>
void Solver<Real>::detach_leaf(SimState& state, size_t leaf) {
  const uint32_t c = model.leaf_cluster[leaf];
  const uint32_t a = model.leaf_attachment_vertex[leaf];
  const bool goes_with_leaf = model.vertex_leaf[a] == static_cast<int32_t>(leaf);
  for (uint32_t s = model.vertex_cluster_offsets[a]; s < model.vertex_cluster_offsets[a + 1]; ++s) {
    const uint32_t slot = model.vertex_memberships[s];
    const uint32_t owner = member_cluster[slot];
    if ((owner == c) == goes_with_leaf || !member_active[slot]) continue;
    member_active[slot] = 0;
    member_in_fit[slot] = 0;
    member_correction.row(slot).setZero();
    if (owner != c) rebuild_cluster_rest(owner);
  }
  cluster_pin_slot[c] = kNone;  // a flying leaf turns about its centre: new rest data, once
  rebuild_cluster_rest(c);
  uint32_t active = 0, first = kNone;
  for (uint32_t s = model.vertex_cluster_offsets[a]; s < model.vertex_cluster_offsets[a + 1]; ++s) {
    const uint32_t slot = model.vertex_memberships[s];
    if (!member_active[slot]) continue;
    ++active;
    if (first == kNone) first = member_cluster[slot];
  }
  vertex_inv_count[a] = active ? 1.0 / active : 0.0;
  if (first != kNone) vertex_air_cluster[a] = first;
  cluster_flying[c] = 1;
  for (uint32_t s = model.cluster_offsets[c]; s < model.cluster_offsets[c + 1]; ++s) {
    const uint32_t v = model.cluster_members[s];
    if (!member_active[s] || model.vertex_leaf[v] != static_cast<int32_t>(leaf) || model.vertex_anchored[v]) continue;
    vertex_flying[v] = 1;
    vertex_global[v] = 0;  // the rest pose no longer holds a flying leaf
  }
  applied_attached[leaf] = 0;
  state.leaf_attached[leaf] = 0;
}

// state.leaf_attached => the arrays of this simulator (a state may come from a checkpoint);
// true when a leaf was detached here.
template <typename Real>
bool Solver<Real>::sync_detachments(SimState& state) {
  bool changed = false;
  for (size_t l = 0; l < L; ++l) {
    if (state.leaf_attached[l] == applied_attached[l]) continue;
    if (state.leaf_attached[l]) throw SimulationError("leaf " + std::to_string(l) + " was re-attached: leaves never re-attach");
    detach_leaf(state, l);
    changed = true;
  }
  return changed;
}

// t => the wind terms shared by every cluster at t (base wind, turbulence amplitude and
// temporal phases), for sample_cluster_air.
template <typename Real>
void Solver<Real>::set_air_time(double t) {
  air_base = wind.base(t);
  air_scale = wind.temporal_phases(t, turbulence_sin_b, turbulence_cos_b);
}

// Air velocity at cluster c (its rest centre; a flying leaf: its centre of the last fit).
template <typename Real>
void Solver<Real>::sample_cluster_air(size_t c) {
  const int N = wind.mode_count();
  if (cluster_flying[c]) {
    double sin_a[kMaxModes], cos_a[kMaxModes];
    wind.spatial_phases(Eigen::Vector3d(cluster_rest_centre.col(c) + cluster_shift.col(c)), sin_a, cos_a);
    const Eigen::Vector3d air = air_base + wind.turbulence(sin_a, cos_a, turbulence_sin_b, turbulence_cos_b, air_scale);
    cluster_air.row(c) = air.transpose().template cast<Real>();
  } else {
    const Eigen::Vector3d air = air_base + wind.turbulence(&cluster_turbulence_sin[c * N], &cluster_turbulence_cos[c * N],
                                                           turbulence_sin_b, turbulence_cos_b, air_scale);
    cluster_air.row(c) = air.transpose().template cast<Real>();
  }
}

// Air velocity of every awake cluster (at the start of a frame; later steps sample it in
// match_clusters, saving a parallel region per step).
template <typename Real>
void Solver<Real>::sample_air(const SimState& state) {
#pragma omp parallel for schedule(static) if (parallel)
  for (size_t c = 0; c < C; ++c)
    if (cluster_awake(state, c)) sample_cluster_air(c);
}

// The per-vertex pass, in displacements from rest (u = x - x0). kStep and kEnd finish the
// current step from the predicted state (averaged corrections, Eq. 7); all three start the
// next step (damping, drag, gravity, global term Eq. 8, which is -k u / h) into v*
// (`step_velocity`) and u_p = u + h v* (`predicted_offset`). Fused, so a vertex is loaded
// once per substep. kStart predicts from state.positions and velocities (the first step of
// a frame without a carried prediction); kEnd, the last step of a frame, also writes
// positions and velocities to the state, and its prediction is the next frame's first.
// Returns whether an island was asleep (its vertices were skipped, so their prediction is
// not current).
template <typename Real>
bool Solver<Real>::vertex_pass(SimState& state, Pass pass, long long frame, int substep) {
  const bool any_asleep = std::any_of(state.island_asleep.begin(), state.island_asleep.end(),
                                      [](uint8_t a) { return a != 0; });
  uint32_t bad = kNone, runaway = kNone;
#pragma omp parallel if (parallel) reduction(min : bad, runaway)
  {
    const auto [first, last] =
        balanced_range(model.vertex_cluster_offsets, omp_get_thread_num(), omp_get_num_threads());
    // Without sleeping islands every free vertex moves and reads its mean correction from
    // one row (anchors: the zero row, with factors that keep them still); otherwise, and when
    // a frame starts from the state, each block is gathered lane by lane.
    const bool direct = pass != Pass::kStart && !any_asleep;
    if (direct) average_shared_pulls(first, last);
    const Real* corrections[3] = {member_correction.col(0).data(), member_correction.col(1).data(),
                                    member_correction.col(2).data()};
    Block block;
    for (size_t begin = first; begin < last; begin += kVertexBlock) {
      const int n = static_cast<int>(std::min<size_t>(kVertexBlock, last - begin));
      Inputs in;
      if (direct) {
        in = {{corrections[0], corrections[1], corrections[2]}, vertex_pull_row.data() + begin,
              vertex_drag.data() + begin, vertex_damping.data() + begin, vertex_global.data() + begin,
              vertex_flying.data() + begin};
        std::fill(block.moving, block.moving + n, uint8_t(1));
      } else {
        gather_block(state, pass, any_asleep, begin, n, block);
        in = {{block.pull[0], block.pull[1], block.pull[2]}, kLaneIndex.data(), block.drag, block.damping,
              block.global, block.flying};
      }
      const bool end = pass == Pass::kEnd;
      const bool flagged = end ? (detach_enabled ? predict_block<true, true>(begin, n, in, block)
                                                 : predict_block<true, false>(begin, n, in, block))
                               : (detach_enabled ? predict_block<false, true>(begin, n, in, block)
                                                 : predict_block<false, false>(begin, n, in, block));
      if (end) {
        // (3 x V) columns: x, y, z of a vertex are adjacent. A still lane keeps its value.
        double* positions = state.positions.data() + 3 * begin;
        double* velocities = state.velocities.data() + 3 * begin;
        const double* rest = model.rest_positions.data() + 3 * begin;
#pragma omp simd
        for (int k = 0; k < n; ++k)
          for (int i = 0; i < 3; ++i) {
            const bool moving = block.moving[k] != 0;
            positions[3 * k + i] = moving ? rest[3 * k + i] + double(block.end_offset[i][k]) : positions[3 * k + i];
            velocities[3 * k + i] = moving ? double(block.end_velocity[i][k]) : velocities[3 * k + i];
          }
      }
      if (flagged) {  // rare: find the first vertex at fault, as the scalar tests would
        for (int k = 0; k < n; ++k) {
          if (!block.moving[k]) continue;
          const uint32_t v = static_cast<uint32_t>(begin + k);
          if (!predicted_offset.row(v).allFinite() || !step_velocity.row(v).allFinite() ||
              (end && !(state.positions.col(v).allFinite() && state.velocities.col(v).allFinite())))
            bad = std::min(bad, v);
          const double moved2 = end ? Vector3(block.end_offset[0][k], block.end_offset[1][k], block.end_offset[2][k])
                                          .template cast<double>()
                                          .squaredNorm()
                                    : 0.0;
          if (!vertex_flying[v] && moved2 > runaway_distance2) runaway = std::min(runaway, v);
        }
      }
    }
  }
  // Vertex v => "frame F, substep S, cluster C (vertex v): " for the messages below.
  auto where = [&](uint32_t v) {
    return "frame " + std::to_string(frame) + ", substep " + std::to_string(substep) + ", cluster " +
           std::to_string(vertex_air_cluster[v]) + " (vertex " + std::to_string(v) + "): ";
  };
  if (bad != kNone) throw SimulationError(where(bad) + "non-finite position or velocity");
  if (runaway != kNone) {
    char distances[96];
    std::snprintf(distances, sizeof distances, "moved %.3g m from rest, more than twice the tree's size (%.3g m)",
                  (state.positions.col(runaway) - model.rest_positions.col(runaway)).norm(),
                  std::sqrt(runaway_distance2) / 2);
    throw SimulationError(where(runaway) + distances +
                          ": the tree came apart; raise time.substeps or the stiffness (docs/solver.md, \"Runaway\")");
  }
  return any_asleep;
}

// Shared vertices in [first, last) => their mean correction in the row of their first
// membership, read by the direct vertex pass.
template <typename Real>
void Solver<Real>::average_shared_pulls(size_t first, size_t last) {
  const auto from = std::lower_bound(shared_vertices.begin(), shared_vertices.end(), first);
  const auto to = std::lower_bound(from, shared_vertices.end(), last);
  for (auto it = from; it != to; ++it) member_correction.row(vertex_pull_row[*it]) = mean_correction(*it);
}

// Vertices [begin, begin + n) => block.moving (0: anchored, without an active cluster, or
// asleep) and block.pull, each vertex's mean correction; kStart: 0, after loading u = x - x0
// and v from the state (anchors included: they hold where they are).
template <typename Real>
void Solver<Real>::gather_block(const SimState& state, Pass pass, bool any_asleep, size_t begin, int n,
                                   Block& block) {
  for (int k = 0; k < n; ++k) {
    const size_t v = begin + k;
    const bool still = model.vertex_anchored[v] || vertex_inv_count[v] == 0 ||
                       (any_asleep && !vertex_flying[v] && state.island_asleep[vertex_island[v]]);
    block.moving[k] = still ? 0 : 1;
    block.drag[k] = still ? Real(0) : vertex_drag[v];
    block.damping[k] = still ? Real(1) : vertex_damping[v];
    block.global[k] = still ? Real(0) : vertex_global[v];
    block.flying[k] = still ? 0 : vertex_flying[v];
    Vector3 pull = Vector3::Zero();
    if (pass == Pass::kStart) {
      predicted_offset.row(v) = (state.positions.col(v) - model.rest_positions.col(v)).transpose().template cast<Real>();
      step_velocity.row(v) = state.velocities.col(v).transpose().template cast<Real>();
    } else if (!still) {
      pull = mean_correction(static_cast<uint32_t>(v)).transpose();
    }
    for (int i = 0; i < 3; ++i) block.pull[i][k] = pull[i];
  }
}

// Corrected vertices of a block => their prediction for the next step, written for the
// moving ones; with `kEnd` also the corrected u and v in block.end_*. One loop without
// branches, vectorised across vertices: the drag's square root and division dominate it.
// Returns true when some moving vertex turned non-finite or (kEnd) ran away; the caller
// finds which.
template <typename Real>
template <bool kEnd, bool kDetach>
bool Solver<Real>::predict_block(size_t begin, int n, const Inputs& in, Block& block) {
  const Real inv_h = static_cast<Real>(1.0 / h), step = static_cast<Real>(h);
  const Real gravity_step[3] = {static_cast<Real>(options.gravity.x() * h), static_cast<Real>(options.gravity.y() * h),
                                static_cast<Real>(options.gravity.z() * h)};
  const Real* air[3] = {cluster_air.col(0).data(), cluster_air.col(1).data(), cluster_air.col(2).data()};
  Real* force[3] = {nullptr, nullptr, nullptr};
  if constexpr (kDetach)
    for (int i = 0; i < 3; ++i) force[i] = vertex_drag_force.col(i).data() + begin;
  const uint32_t* air_cluster = vertex_air_cluster.data() + begin;
  const double* mass = model.vertex_mass.data() + begin;
  const Real limit2 = static_cast<Real>(runaway_distance2);
  Real *offset_x = predicted_offset.col(0).data() + begin, *offset_y = predicted_offset.col(1).data() + begin,
         *offset_z = predicted_offset.col(2).data() + begin;
  Real *velocity_x = step_velocity.col(0).data() + begin, *velocity_y = step_velocity.col(1).data() + begin,
         *velocity_z = step_velocity.col(2).data() + begin;
#pragma omp simd
  for (int k = 0; k < n; ++k) {
    const uint32_t c = air_cluster[k], row = in.pull_row[k];
    const Real px = in.pull[0][row], py = in.pull[1][row], pz = in.pull[2][row];
    const Real ux = offset_x[k] + px, uy = offset_y[k] + py, uz = offset_z[k] + pz;
    const Real vx = velocity_x[k] + px * inv_h, vy = velocity_y[k] + py * inv_h, vz = velocity_z[k] + pz * inv_h;
    // A flying leaf falls (its global rate is 0); an attached vertex is pulled back. These
    // impulses first, then the quadratic drag integrated exactly over the step for constant
    // air velocity from the velocity they left: du/dt = -k|u|u gives |u(h)| = |u0| / (1 + k|u0|h),
    // so the change never overshoots the air velocity, whatever the wind speed or step. In
    // this order the drag damps the whole step (for linear drag: backward Euler on all of it)
    // and a vertex held by its pull back rests where pull and drag balance; with the drag
    // first, the pull was not damped and a leaf rested off by k|u|h (3 % at the default step).
    const Real damping = in.damping[k], falling = static_cast<Real>(in.flying[k]), pull_back = in.global[k] * inv_h;
    const Real fx = (vx * damping + falling * gravity_step[0]) - pull_back * ux;
    const Real fy = (vy * damping + falling * gravity_step[1]) - pull_back * uy;
    const Real fz = (vz * damping + falling * gravity_step[2]) - pull_back * uz;
    const Real rx = air[0][c] - fx, ry = air[1][c] - fy, rz = air[2][c] - fz;
    const Real kuh = in.drag[k] * std::sqrt(rx * rx + ry * ry + rz * rz) * step;
    const Real share = kuh / (1 + kuh);
    const Real nx = fx + rx * share, ny = fy + ry * share, nz = fz + rz * share;
    const Real ax = ux + step * nx, ay = uy + step * ny, az = uz + step * nz;
    velocity_x[k] = nx;
    velocity_y[k] = ny;
    velocity_z[k] = nz;
    offset_x[k] = ax;
    offset_y[k] = ay;
    offset_z[k] = az;
    if constexpr (kDetach) {
      const Real scale = static_cast<Real>(mass[k]) * inv_h;
      force[0][k] = rx * share * scale;
      force[1][k] = ry * share * scale;
      force[2][k] = rz * share * scale;
    }
    Real sum = ((ax + nx) + (ay + ny)) + (az + nz);
    Real excess = 0;  // > 0: an attached vertex ran away (kEnd)
    if constexpr (kEnd) {
      block.end_offset[0][k] = ux;
      block.end_offset[1][k] = uy;
      block.end_offset[2][k] = uz;
      block.end_velocity[0][k] = vx;
      block.end_velocity[1][k] = vy;
      block.end_velocity[2][k] = vz;
      sum += (vx + vy) + vz;
      excess = (1 - falling) * (ux * ux + uy * uy + uz * uz) - limit2;
    }
    block.check[k] = sum;
    block.excess[k] = excess;
  }
  // One test for the block: a sum of finite values is finite (it only overflows far past any
  // tree, and then the caller's rescan finds nothing). Kept out of the loop above: a
  // reduction there stops GCC from vectorising it. The order of the sum decides nothing.
  Real total = 0, worst = 0;
#pragma omp simd reduction(+ : total) reduction(max : worst)
  for (int k = 0; k < n; ++k) {
    total += block.check[k];
    worst = std::max(worst, block.excess[k]);
  }
  return !(total - total == 0) || worst > 0;
}

// Shape match of cluster c on the predicted positions, pinned_point: the displacement from
// rest of its match point o where that point is held (an attached leaf), nullptr where the
// point is the centre and follows the members => its rotation R (warm start updated) and its
// translation as t - t0, for goals R q + t; false when a value is not finite.
template <typename Real>
bool Solver<Real>::fit_cluster(SimState& state, size_t c, const Eigen::Vector3d* pinned_point, Eigen::Matrix3d& R,
                               Eigen::Vector3d& shift) {
  const uint32_t begin = model.cluster_offsets[c], end = model.cluster_offsets[c + 1];
  // Cluster-local coordinates: d = p - t0 = u_p + q (x0 - t0 = q for a member), small
  // numbers wherever the tree stands and however far it travelled. With the rest terms
  // precomputed, one pass over the displacements sums the centre shift
  // t - t0 = sum (w / sum w) u_p and sum s u_p q^T, s = (w / sum w) k with the cluster's
  // match scale k. About the match point o, displaced by w (the centre shift, or the pin):
  // A_pq = sum s (d - o - w)(q - o)^T = sum s u_p q^T - k shift o^T + sum s (q - o)(q - o)^T
  //        - w (sum s (q - o))^T,
  // the third term precomputed. About the centre, sum s q is 0 but for the round-off of the
  // stored q; the shift leaves that residue out, so at the rest pose (u_p = 0) the shift is
  // exactly 0, A_pq is the exactly symmetric rest moment and no goal pulls a resting tree (in
  // float the residue is ~1e-8 m, and the slow global term would let it creep ~1e-4 m). One
  // weight per member serves both sums; they run in Real, with the round-off of the values
  // they sum. q is read here and again by write_corrections, while it is in cache.
  Real a00 = 0, a01 = 0, a02 = 0, a10 = 0, a11 = 0, a12 = 0, a20 = 0, a21 = 0, a22 = 0;
  Real sx = 0, sy = 0, sz = 0;
  for (uint32_t s = begin; s < end; ++s) {
    const uint32_t v = model.cluster_members[s];
    const Real x = predicted_offset(v, 0), y = predicted_offset(v, 1), z = predicted_offset(v, 2);
    const Real share = member_centre_weight[s];
    const Real wx = share * member_offset(s, 0), wy = share * member_offset(s, 1), wz = share * member_offset(s, 2);
    sx += share * x, sy += share * y, sz += share * z;
    a00 += x * wx, a01 += x * wy, a02 += x * wz;
    a10 += y * wx, a11 += y * wy, a12 += y * wz;
    a20 += z * wx, a21 += z * wy, a22 += z * wz;
  }
  const Eigen::Vector3d centre_shift(sx, sy, sz);
  const Eigen::Vector3d point = cluster_match_point.col(c);
  const Eigen::Vector3d point_shift = pinned_point ? *pinned_point : centre_shift;
  Eigen::Matrix3d A;
  A << double(a00), double(a01), double(a02), double(a10), double(a11), double(a12), double(a20), double(a21), double(a22);
  A -= centre_shift * point.transpose();  // 0 about the centre
  A *= cluster_match_scale[c];
  A += Eigen::Map<const Eigen::Matrix3d>(&cluster_rest_moment(0, c));
  A -= point_shift * cluster_offset_sum.col(c).transpose();
  Eigen::Quaterniond rotation(state.cluster_rotations.col(c));
  extract_rotation(A, rotation, options.rotation_iterations);
  state.cluster_rotations.col(c) = rotation.coeffs();
  R = rotation.toRotationMatrix();
  // The goal of the match point is o + w: t - t0 = w - (R - I) o (w itself about the centre).
  shift = point_shift - (R * point - point);
  cluster_shift.col(c) = shift;
  Eigen::Map<Eigen::Matrix3d>(&cluster_rotation_matrix(0, c)) = R;
  return R.allFinite() && shift.allFinite();
}

// Goals g = R q + t of cluster c, with t given as t - t0 => per-membership corrections
// alpha_c (g - p) = alpha_c ((R q - q) + (t - t0) - u_p).
template <typename Real>
void Solver<Real>::write_corrections(size_t c, const Eigen::Matrix3d& R, const Eigen::Vector3d& shift) {
  const Real alpha = static_cast<Real>(cluster_alpha[c]);
  const uint32_t* members = model.cluster_members.data();
  const uint8_t* active = member_active.data();
  const Real *qx = member_offset.col(0).data(), *qy = member_offset.col(1).data(), *qz = member_offset.col(2).data();
  const Real *ux = predicted_offset.col(0).data(), *uy = predicted_offset.col(1).data(),
             *uz = predicted_offset.col(2).data();
  Real *cx = member_correction.col(0).data(), *cy = member_correction.col(1).data(), *cz = member_correction.col(2).data();
  const Eigen::Matrix<Real, 3, 3> r = R.template cast<Real>();
  const Vector3 t = shift.template cast<Real>();
  const Real r00 = r(0, 0), r01 = r(0, 1), r02 = r(0, 2), r10 = r(1, 0), r11 = r(1, 1), r12 = r(1, 2);
  const Real r20 = r(2, 0), r21 = r(2, 1), r22 = r(2, 2), tx = t.x(), ty = t.y(), tz = t.z();
#pragma omp simd
  for (uint32_t s = model.cluster_offsets[c]; s < model.cluster_offsets[c + 1]; ++s) {
    const uint32_t v = members[s];
    const Real x = qx[s], y = qy[s], z = qz[s];
    const Real weight = active[s] ? alpha : Real(0);  // a released membership pulls nothing
    cx[s] = weight * ((((r00 * x + r01 * y) + r02 * z) - x) + tx - ux[v]);
    cy[s] = weight * ((((r10 * x + r11 * y) + r12 * z) - y) + ty - uy[v]);
    cz[s] = weight * ((((r20 * x + r21 * y) + r22 * z) - z) + tz - uz[v]);
  }
}

// Predicted positions => corrections of every awake cluster: branches and free leaves first,
// then the attached leaves, whose translation is pinned to their branch's goal for the shared
// vertex (hierarchical: a 1 g leaf cannot drag its branch, nor drift off it in a gale).
// Each cluster also samples the air of the next step (set_air_time) for the prediction.
template <typename Real>
void Solver<Real>::match_clusters(SimState& state, long long frame, int substep) {
  uint32_t bad = kNone;
#pragma omp parallel if (parallel) reduction(min : bad)
  {
    const auto [first, last] = balanced_range(model.cluster_offsets, omp_get_thread_num(), omp_get_num_threads());
    for (size_t c = first; c < last; ++c) {
      if (!cluster_awake(state, c)) continue;
      if (cluster_pin_slot[c] == kNone) {
        Eigen::Matrix3d R;
        Eigen::Vector3d shift;
        if (fit_cluster(state, c, nullptr, R, shift)) write_corrections(c, R, shift);
        else bad = std::min(bad, static_cast<uint32_t>(c));
      }
      sample_cluster_air(c);
    }
    if (!pinned_leaf_clusters.empty()) {
#pragma omp barrier
#pragma omp for schedule(static)
      for (size_t k = 0; k < pinned_leaf_clusters.size(); ++k) {
        const uint32_t c = pinned_leaf_clusters[k];
        if (cluster_pin_slot[c] == kNone || !cluster_awake(state, c)) continue;
        // The leaf turns about its shared vertex, held at its branch's goal for it,
        // t0_b + shift_b + R_b q_b: as a displacement from the vertex's rest position
        // t0_b + q_b that is shift_b + (R_b - I) q_b, written without the rest terms that
        // cancel (their round-off, ~1e-8 m for float offsets, would pull every resting leaf).
        // About that vertex, not about the leaf's centre: a rigid leaf pinned at its petiole
        // turns by the torque about the petiole, and the pinned vertex itself, which never
        // quite reaches its goal (its branch corrects it by alpha_b per step), has no lever.
        // About the centre, that lag entered the leaf's torque and the leaf's rest angle in a
        // steady wind changed with the step as (omega_b h)^2 (docs/solver.md, "Leaves").
        const uint32_t pin = cluster_pin_slot[c];
        const uint32_t branch = member_cluster[pin];
        const Eigen::Vector3d branch_offset = member_offset.row(pin).transpose().template cast<double>();
        const Eigen::Vector3d held =
            cluster_shift.col(branch) +
            (Eigen::Map<const Eigen::Matrix3d>(&cluster_rotation_matrix(0, branch)) * branch_offset - branch_offset);
        Eigen::Matrix3d R;
        Eigen::Vector3d shift;
        if (!fit_cluster(state, c, &held, R, shift)) {
          bad = std::min(bad, c);
          continue;
        }
        write_corrections(c, R, shift);
      }
    }
  }
  if (bad != kNone)
    throw SimulationError("frame " + std::to_string(frame) + ", substep " + std::to_string(substep) + ", cluster " +
                          std::to_string(bad) + ": the shape match produced a non-finite rotation or centre");
}

// Drag on each attached leaf => detach those past the threshold (in leaf order).
template <typename Real>
void Solver<Real>::check_detachments(SimState& state) {
  for (size_t l = 0; l < L; ++l) {
    if (!state.leaf_attached[l]) continue;
    const uint32_t c = model.leaf_cluster[l];
    Eigen::Vector3d force = Eigen::Vector3d::Zero();
    for (uint32_t s = model.cluster_offsets[c]; s < model.cluster_offsets[c + 1]; ++s) {
      const uint32_t v = model.cluster_members[s];
      if (model.vertex_leaf[v] == static_cast<int32_t>(l)) force += vertex_drag_force.row(v).transpose().template cast<double>();
    }
    if (force.norm() > options.leaf_detach_force) detach_leaf(state, l);
  }
}

// End of a frame at time t: an awake island in calm air whose vertices all rest (slower than
// sleep_velocity, closer than sleep_distance to rest) is put to sleep exactly at rest;
// true when one was.
template <typename Real>
bool Solver<Real>::check_sleep(SimState& state, double t) {
  if (!wind.calm(t)) return false;
  bool fell_asleep = false;
  const double v2 = options.sleep_velocity * options.sleep_velocity;
  const double d2 = options.sleep_distance * options.sleep_distance;
  for (size_t i = 0; i < I; ++i) {
    if (state.island_asleep[i]) continue;
    bool rests = true;
    for (uint32_t k = island_vertex_offsets[i]; rests && k < island_vertex_offsets[i + 1]; ++k) {
      const uint32_t v = island_vertices[k];
      if (vertex_flying[v]) continue;
      rests = state.velocities.col(v).squaredNorm() < v2 &&
              (state.positions.col(v) - model.rest_positions.col(v)).squaredNorm() < d2;
    }
    if (!rests) continue;
    state.island_asleep[i] = 1;
    fell_asleep = true;
    island_fell_asleep[i] = 1;
    for (uint32_t k = island_vertex_offsets[i]; k < island_vertex_offsets[i + 1]; ++k) {
      const uint32_t v = island_vertices[k];
      if (vertex_flying[v]) continue;
      state.positions.col(v) = model.rest_positions.col(v);
      state.velocities.col(v).setZero();
    }
  }
  // At the rest pose every rotation is the identity (exactly: A_pq is symmetric there).
  for (size_t c = 0; c < C; ++c)
    if (island_fell_asleep[cluster_island[c]] && !cluster_flying[c])
      state.cluster_rotations.col(c) = Eigen::Quaterniond::Identity().coeffs();
  std::fill(island_fell_asleep.begin(), island_fell_asleep.end(), 0);
  return fell_asleep;
}

// True when no island is awake and nothing flies: the frame costs nothing.
template <typename Real>
bool Solver<Real>::all_resting(const SimState& state) const {
  return std::all_of(state.island_asleep.begin(), state.island_asleep.end(), [](uint8_t a) { return a != 0; }) &&
         std::none_of(cluster_flying.begin(), cluster_flying.end(), [](uint8_t f) { return f != 0; });
}

// One frame of `substeps` steps from state.time: predict, then per step match the clusters
// and correct, fused with the next step's prediction.
template <typename Real>
void Solver<Real>::frame(SimState& state, long long frame_index) {
  const double start = state.time;
  // The last step of the previous frame predicted this frame's first step for exactly this
  // state, unless something changed it since (the stamp is reset below until this frame ends).
  const bool carried = carried_stamp != 0 && state.prediction_stamp == carried_stamp;
  state.prediction_stamp = carried_stamp = 0;
  if (options.sleep) {
    // Sleeping islands wake as soon as the air moves at any step of this frame.
    bool calm = true;
    for (int k = 0; k < substeps && calm; ++k) calm = wind.calm(start + k * h);
    if (!calm) std::fill(state.island_asleep.begin(), state.island_asleep.end(), 0);
    if (all_resting(state)) return;
  }
  if (!carried) {
    set_air_time(start);
    sample_air(state);
    vertex_pass(state, Pass::kStart, frame_index, 0);
  }
  if (detach_enabled) check_detachments(state);
  bool skipped_sleepers = false;
  for (int k = 0; k < substeps; ++k) {
    const bool last = k + 1 == substeps;
    // The air of step k was used by its prediction, so the scratch can move on to k + 1
    // (after the last step: the next frame's first).
    set_air_time(last ? start + frame_dt : start + (k + 1) * h);
    match_clusters(state, frame_index, k);
    skipped_sleepers = vertex_pass(state, last ? Pass::kEnd : Pass::kStep, frame_index, k);
    if (!last && detach_enabled) check_detachments(state);
  }
  if (!skipped_sleepers) state.prediction_stamp = carried_stamp = ++stamps_issued;
}

template <typename Real>
SimState Solver<Real>::initial_state(double time) const {
  SimState state;
  state.positions = model.rest_positions;
  state.velocities.setZero(3, V);
  state.leaf_attached.assign(L, 1);
  state.time = time;
  state.cluster_rotations.resize(4, C);
  for (size_t c = 0; c < C; ++c) state.cluster_rotations.col(c) = Eigen::Quaterniond::Identity().coeffs();
  // At rest in calm air there is nothing to do until the wind rises.
  state.island_asleep.assign(I, options.sleep && wind.calm(time) ? 1 : 0);
  return state;
}

template <typename Real>
void Solver<Real>::advance_frame(SimState& state, long long frame_index) {
  if (state.positions.cols() != static_cast<Eigen::Index>(V) || state.leaf_attached.size() != L ||
      state.cluster_rotations.cols() != static_cast<Eigen::Index>(C) || state.island_asleep.size() != I)
    throw SimulationError("frame " + std::to_string(frame_index) + ": the state does not belong to this tree model");
  if (sync_detachments(state)) state.prediction_stamp = 0;
  frame(state, frame_index);
  state.time += frame_dt;
  // An island put to sleep is moved to its rest pose: its carried prediction no longer holds.
  if (options.sleep && check_sleep(state, state.time)) state.prediction_stamp = carried_stamp = 0;
}

}  // namespace

Simulator::Simulator(const TreeModel& model, const SimOptions& options, const WindOptions& wind,
                     double frame_dt, int substeps) {
  if (options.precision == Precision::kFloat)
    impl_ = std::make_unique<Solver<float>>(model, options, wind, frame_dt, substeps);
  else
    impl_ = std::make_unique<Solver<double>>(model, options, wind, frame_dt, substeps);
}

Simulator::~Simulator() = default;

SimState Simulator::initial_state(double time) const { return impl_->initial_state(time); }

void Simulator::advance_frame(SimState& state, long long frame) { impl_->advance_frame(state, frame); }

}  // namespace treeanim
