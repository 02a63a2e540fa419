// Precompute (libigl's split of a solver into precompute + solve): TreeModel + options =>
// SolverModel, whose Attachment has every leaf attached; and the per-step scratch.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

#include "common/errors.h"
#include "sim/bar_chain.h"
#include "sim/rotation.h"
#include "sim/solver_step.h"
#include "sim/stiffness.h"

namespace treeanim {

namespace {

// Union-find root with path halving.
uint32_t find_root(std::vector<uint32_t>& parent, uint32_t a) {
  while (parent[a] != a) a = parent[a] = parent[parent[a]];
  return a;
}

// The leaves whose four vertices are a card (SolverModel::leaf_cards), in vertex order.
std::vector<LeafCard> leaf_cards(const TreeModel& tree) {
  std::vector<LeafCard> cards;
  const uint32_t *offsets = tree.vertex_cluster_offsets.data(), *memberships = tree.vertex_memberships.data();
  for (size_t l = 0; l < tree.leaf_count(); ++l) {
    const uint32_t c = tree.leaf_cluster[l], v = tree.leaf_attachment_vertex[l], slot = tree.cluster_offsets[c];
    bool card = tree.cluster_offsets[c + 1] - slot == 4 && offsets[v + 1] - offsets[v] == 2 &&
                memberships[offsets[v] + 1] == slot;
    for (uint32_t k = 0; card && k < 4; ++k)
      card = tree.cluster_members[slot + k] == v + k && (k == 0 || (offsets[v + k + 1] - offsets[v + k] == 1 &&
                                                                    memberships[offsets[v + k]] == slot + k));
    if (card) cards.push_back({v, c, slot, tree.member_cluster[memberships[offsets[v]]], memberships[offsets[v]]});
  }
  std::sort(cards.begin(), cards.end(), [](const LeafCard& a, const LeafCard& b) { return a.vertex < b.vertex; });
  return cards;
}

// Model CSR => per-membership cluster ids, and per vertex its counts, correction row and
// air cluster (the rest data comes from rebuild_cluster_rest, once the pins are known).
template <typename Real>
void precompute_members(SolverModel<Real>& m, Attachment<Real>& a) {
  const TreeModel& tree = m.tree;
  a.member_offset.setZero(m.M, 3);
  a.member_centre_weight.assign(m.M, 0);
  a.member_active.assign(m.M, 1);
  a.member_in_fit.assign(m.M, 1);
  a.cluster_rest_centre.setZero(3, m.C);
  a.cluster_match_point.setZero(3, m.C);
  a.cluster_match_scale.assign(m.C, 0);
  a.cluster_offset_sum.setZero(3, m.C);
  a.cluster_rest_moment.setZero(9, m.C);
  a.vertex_inv_count.assign(m.V, 0);
  a.vertex_air_cluster.assign(m.V, 0);
  // A free vertex's only membership writes to the vertex's row; every other membership gets a
  // row past V, in membership order (a cluster's ring of shared vertices stays consecutive).
  m.member_correction_row.assign(m.M, kNone);
  for (size_t v = 0; v < m.V; ++v) {
    const uint32_t begin = tree.vertex_cluster_offsets[v], end = tree.vertex_cluster_offsets[v + 1];
    if (!tree.vertex_anchored[v] && end - begin == 1) m.member_correction_row[tree.vertex_memberships[begin]] = v;
  }
  m.correction_rows = m.V;
  for (uint32_t& row : m.member_correction_row)
    if (row == kNone) row = static_cast<uint32_t>(m.correction_rows++);
  m.correction_run_offsets.assign(1, 0);
  for (size_t c = 0; c < m.C; ++c) {
    for (uint32_t s = tree.cluster_offsets[c]; s < tree.cluster_offsets[c + 1]; ++s) {
      const uint32_t row = m.member_correction_row[s];
      CorrectionRun* run = m.correction_runs.size() > m.correction_run_offsets.back() ? &m.correction_runs.back() : nullptr;
      if (run && run->row + (s - run->begin) == row && (run->row < m.V) == (row < m.V))
        run->end = s + 1;  // the next row, of the same kind (a vertex's own, or a membership's)
      else
        m.correction_runs.push_back({s, s + 1, row});
    }
    m.correction_run_offsets.push_back(static_cast<uint32_t>(m.correction_runs.size()));
  }
  m.shared_row_offsets.assign(1, 0);
  for (size_t v = 0; v < m.V; ++v) {
    const uint32_t begin = tree.vertex_cluster_offsets[v], end = tree.vertex_cluster_offsets[v + 1];
    a.vertex_inv_count[v] = end > begin ? Real(1) / Real(end - begin) : Real(0);
    a.vertex_air_cluster[v] = end > begin ? tree.member_cluster[tree.vertex_memberships[begin]] : 0;
    if (tree.vertex_anchored[v] || end - begin < 2) continue;
    m.shared_vertices.push_back(static_cast<uint32_t>(v));
    for (uint32_t s = begin; s < end; ++s)
      m.shared_correction_rows.push_back(m.member_correction_row[tree.vertex_memberships[s]]);
    m.shared_row_offsets.push_back(static_cast<uint32_t>(m.shared_correction_rows.size()));
  }
  // A leaf's shared vertex is in no run: its memberships may be released. Nor is a card's.
  std::vector<uint8_t> excluded(m.V, 0);
  for (size_t l = 0; l < m.L; ++l) excluded[tree.leaf_attachment_vertex[l]] = 1;
  m.leaf_cards = leaf_cards(tree);
  for (const LeafCard& card : m.leaf_cards) std::fill_n(excluded.begin() + card.vertex, 4, uint8_t(1));
  m.vertex_runs = vertex_runs(tree, excluded);
}

// Leaves => the membership slots that pin each attached leaf to its branch (attached_leaves.cpp).
// A leaf whose shared vertex is in no other cluster is matched like a branch. The shared
// vertex, where it is the leaf's own, does not count in its branch's fit: it carries leaf
// mass and drag, and the leaf's drag reaches its branch through the bar chain, not through
// the branch's fit (docs/solver.md, "Leaves").
template <typename Real>
void precompute_pins(SolverModel<Real>& m, Attachment<Real>& a) {
  const TreeModel& tree = m.tree;
  a.cluster_pin_slot.assign(m.C, kNone);
  m.cluster_pin_own_slot.assign(m.C, kNone);
  for (size_t l = 0; l < m.L; ++l) {
    const uint32_t c = tree.leaf_cluster[l], shared = tree.leaf_attachment_vertex[l];
    uint32_t own = kNone, pin = kNone;
    for (uint32_t s = tree.vertex_cluster_offsets[shared]; s < tree.vertex_cluster_offsets[shared + 1]; ++s) {
      const uint32_t slot = tree.vertex_memberships[s];
      if (tree.member_cluster[slot] == c) own = slot;
      else if (pin == kNone && tree.cluster_kind[tree.member_cluster[slot]] == kClusterBranch) pin = slot;
    }
    if (own == kNone || pin == kNone) continue;
    a.cluster_pin_slot[c] = pin;
    m.cluster_pin_own_slot[c] = own;
    m.pinned_leaf_clusters.push_back(c);
    if (tree.vertex_leaf[shared] == static_cast<int32_t>(l)) a.member_in_fit[pin] = 0;
  }
}

// The attached leaves (precompute_pins) => each cluster's share of match_clusters' first pass
// (SolverModel::match_work_offsets): its memberships and a fit's fixed work when it is matched
// there, the air alone for a leaf pinned to its branch, which is matched after it.
template <typename Real>
void precompute_match_work(SolverModel<Real>& m, const Attachment<Real>& a) {
  // In memberships: a fit and its rotation cost about as much as 32 of them (some 650
  // instructions against 20, callgrind on table1-211812), the air of a cluster about 8.
  constexpr uint32_t kFitWork = 32, kAirWork = 8;
  const TreeModel& tree = m.tree;
  m.match_work_offsets.assign(1, 0);
  for (size_t c = 0; c < m.C; ++c) {
    const uint32_t matched = tree.cluster_offsets[c + 1] - tree.cluster_offsets[c] + kFitWork;
    m.match_work_offsets.push_back(m.match_work_offsets.back() + kAirWork + (a.cluster_pin_slot[c] == kNone ? matched : 0));
  }
}

// Drag areas and coefficients => per-vertex drag constants.
template <typename Real>
void precompute_drag(SolverModel<Real>& m, const WindOptions& w) {
  const TreeModel& tree = m.tree;
  m.vertex_drag.assign(m.V, 0);
  m.vertex_mass.assign(tree.vertex_mass.begin(), tree.vertex_mass.end());
  for (size_t v = 0; v < m.V; ++v) {
    const double mass = tree.vertex_mass[v];
    if (tree.vertex_anchored[v] || !(mass > 0)) continue;
    const double cd = tree.vertex_leaf[v] >= 0 ? w.leaf_drag_coefficient : w.branch_drag_coefficient;
    m.vertex_drag[v] = static_cast<Real>(0.5 * w.air_density * cd * tree.vertex_drag_area[v] / mass);
  }
}

// Leaf cluster c => the compliance of its petiole, rad/(N m): it turns by options.leaf_turn
// when a 10 m/s wind blows across its blade (a scale-free stiffness: a large leaf has a
// stout petiole). 0 for a leaf without area or arm.
template <typename Real>
double leaf_compliance(const SolverModel<Real>& m, const WindOptions& wind, uint32_t c) {
  const TreeModel& tree = m.tree;
  double area = 0;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (uint32_t s = tree.cluster_offsets[c]; s < tree.cluster_offsets[c + 1]; ++s) {
    const uint32_t v = tree.cluster_members[s];
    area += tree.vertex_drag_area[v];
    centroid += tree.vertex_drag_area[v] * tree.rest_positions.col(v);
  }
  if (!(area > 0)) return 0;
  const double arm = (centroid / area - m.chain.cluster_joint.col(c)).norm();
  const double moment = 0.5 * wind.air_density * wind.leaf_drag_coefficient * area * 100 * arm;  // at 10 m/s
  return moment > 0 ? m.options.leaf_turn / moment : 0;
}

// With the beam: which vertices take their shape correction as a kick, and each leaf's
// petiole compliance and quarter-turn limit added to the bar chain (built in the constructor).
template <typename Real>
void precompute_beam(SolverModel<Real>& m, const WindOptions& wind) {
  m.vertex_shape_kick.assign(m.V, 0);
  if (!m.beam) return;
  m.member_arm.resize(m.M, 3);
  for (size_t s = 0; s < m.M; ++s)
    m.member_arm.row(s) =
        (m.tree.rest_positions.col(m.tree.cluster_members[s]) - m.chain.cluster_joint.col(m.tree.member_cluster[s]))
            .transpose()
            .template cast<Real>();
  if (m.kick)
    for (size_t v = 0; v < m.V; ++v) m.vertex_shape_kick[v] = m.tree.vertex_leaf[v] < 0 ? 1 : 0;
  for (size_t c = 0; c < m.C; ++c)
    if (m.tree.cluster_kind[c] == kClusterLeaf) {
      m.chain.cluster_compliance[c] = leaf_compliance(m, wind, static_cast<uint32_t>(c));
      m.chain.cluster_max_turn[c] = std::numbers::pi / 2;
    }
}

// Clusters sharing a non-anchored vertex => one island (anchors hold, they do not couple).
template <typename Real>
void precompute_islands(SolverModel<Real>& m) {
  const TreeModel& tree = m.tree;
  const size_t V = m.V, C = m.C;
  std::vector<uint32_t> parent(C);
  std::iota(parent.begin(), parent.end(), 0u);
  for (size_t v = 0; v < V; ++v) {
    if (tree.vertex_anchored[v]) continue;
    const uint32_t begin = tree.vertex_cluster_offsets[v], end = tree.vertex_cluster_offsets[v + 1];
    for (uint32_t s = begin + 1; s < end; ++s) {
      const uint32_t a = find_root(parent, tree.member_cluster[tree.vertex_memberships[begin]]);
      const uint32_t b = find_root(parent, tree.member_cluster[tree.vertex_memberships[s]]);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  }
  std::vector<uint32_t> id_of_root(C, kNone);
  m.cluster_island.resize(C);
  m.I = 0;
  for (size_t c = 0; c < C; ++c) {
    const uint32_t r = find_root(parent, static_cast<uint32_t>(c));
    if (id_of_root[r] == kNone) id_of_root[r] = static_cast<uint32_t>(m.I++);
    m.cluster_island[c] = id_of_root[r];
  }
  m.vertex_island.assign(V, kNone);
  m.island_vertex_offsets.assign(m.I + 1, 0);
  for (size_t v = 0; v < V; ++v) {
    const uint32_t begin = tree.vertex_cluster_offsets[v];
    if (tree.vertex_anchored[v] || begin == tree.vertex_cluster_offsets[v + 1]) continue;
    m.vertex_island[v] = m.cluster_island[tree.member_cluster[tree.vertex_memberships[begin]]];
    ++m.island_vertex_offsets[m.vertex_island[v] + 1];
  }
  for (size_t i = 0; i < m.I; ++i) m.island_vertex_offsets[i + 1] += m.island_vertex_offsets[i];
  m.island_vertices.resize(m.island_vertex_offsets[m.I]);
  std::vector<uint32_t> fill(m.island_vertex_offsets.begin(), m.island_vertex_offsets.end() - 1);
  for (size_t v = 0; v < V; ++v)
    if (m.vertex_island[v] != kNone) m.island_vertices[fill[m.vertex_island[v]]++] = static_cast<uint32_t>(v);
}

// Clusters => the step's cache blocks (SolverModel::block_cluster_offsets): the unpinned
// clusters cut into runs of about `block_memberships` memberships with the leaves pinned to
// them (a pinned leaf is matched after its branch), each vertex given to the block holding all
// its clusters, or to the border.
template <typename Real>
void precompute_blocks(SolverModel<Real>& m, size_t block_memberships) {
  const TreeModel& tree = m.tree;
  const size_t blocks = block_memberships ? m.M / block_memberships : 0;
  if (blocks < 2 || m.detach_enabled) return;
  const Attachment<Real>& a = m.all_attached;
  auto size = [&](uint32_t c) { return tree.cluster_offsets[c + 1] - tree.cluster_offsets[c]; };
  std::vector<uint32_t> weight(m.C, 0), leaves_of_offsets(m.C + 1, 0), leaves_of;
  std::vector<uint8_t> pinned(m.C, 0);
  for (uint32_t c : m.pinned_leaf_clusters) {
    pinned[c] = 1;
    ++leaves_of_offsets[tree.member_cluster[a.cluster_pin_slot[c]] + 1];
  }
  for (size_t c = 0; c < m.C; ++c) leaves_of_offsets[c + 1] += leaves_of_offsets[c];
  leaves_of.resize(leaves_of_offsets[m.C]);
  std::vector<uint32_t> fill(leaves_of_offsets.begin(), leaves_of_offsets.end() - 1);
  for (uint32_t c : m.pinned_leaf_clusters) {
    const uint32_t branch = tree.member_cluster[a.cluster_pin_slot[c]];
    leaves_of[fill[branch]++] = c;
    weight[branch] += size(c);
  }
  std::vector<uint32_t> branches, branch_offsets(1, 0);  // the unpinned clusters and their memberships before each
  for (uint32_t c = 0; c < m.C; ++c)
    if (!pinned[c]) {
      branches.push_back(c);
      branch_offsets.push_back(branch_offsets.back() + size(c) + weight[c]);
    }
  std::vector<uint32_t> cluster_block(m.C, kNone);
  m.block_cluster_offsets.assign(1, 0);
  m.block_membership_offsets.assign(1, 0);
  for (size_t b = 0; b < blocks; ++b) {
    const auto [first, last] = balanced_range(branch_offsets, int(b), int(blocks));
    std::vector<uint32_t> leaves;
    for (size_t i = first; i < last; ++i) {
      const uint32_t c = branches[i];
      m.block_clusters.push_back(c);
      leaves.insert(leaves.end(), leaves_of.begin() + leaves_of_offsets[c], leaves_of.begin() + leaves_of_offsets[c + 1]);
    }
    std::sort(leaves.begin(), leaves.end());
    m.block_clusters.insert(m.block_clusters.end(), leaves.begin(), leaves.end());
    for (uint32_t k = m.block_cluster_offsets.back(); k < m.block_clusters.size(); ++k)
      cluster_block[m.block_clusters[k]] = static_cast<uint32_t>(b);
    m.block_cluster_offsets.push_back(static_cast<uint32_t>(m.block_clusters.size()));
    m.block_membership_offsets.push_back(m.block_membership_offsets.back() + branch_offsets[last] - branch_offsets[first]);
  }
  // Each vertex's block, B for the border; each cluster with a border vertex is summed last.
  std::vector<uint32_t> vertex_block(m.V, static_cast<uint32_t>(blocks));
  std::vector<uint8_t> border_cluster(m.C, 0);
  for (size_t v = 0; v < m.V; ++v) {
    const uint32_t begin = tree.vertex_cluster_offsets[v], end = tree.vertex_cluster_offsets[v + 1];
    uint32_t block = begin < end ? cluster_block[tree.member_cluster[tree.vertex_memberships[begin]]] : kNone;
    for (uint32_t s = begin + 1; s < end; ++s)
      if (cluster_block[tree.member_cluster[tree.vertex_memberships[s]]] != block) block = kNone;
    if (block != kNone) vertex_block[v] = block;
    else
      for (uint32_t s = begin; s < end; ++s) border_cluster[tree.member_cluster[tree.vertex_memberships[s]]] = 1;
  }
  std::vector<std::vector<VertexSegment>> segments(blocks + 1);
  for (uint32_t v = 0; v < m.V; ++v) {
    std::vector<VertexSegment>& list = segments[vertex_block[v]];
    if (!list.empty() && list.back().end == v)
      ++list.back().end;
    else
      list.push_back({v, v + 1});
  }
  std::vector<std::vector<uint32_t>> loads(blocks + 1);
  for (uint32_t c = 0; c < m.C; ++c) loads[border_cluster[c] ? blocks : cluster_block[c]].push_back(c);
  m.block_segment_offsets.assign(1, 0);
  m.block_load_offsets.assign(1, 0);
  for (size_t b = 0; b <= blocks; ++b) {
    m.block_segments.insert(m.block_segments.end(), segments[b].begin(), segments[b].end());
    m.block_segment_offsets.push_back(static_cast<uint32_t>(m.block_segments.size()));
    m.block_load_clusters.insert(m.block_load_clusters.end(), loads[b].begin(), loads[b].end());
    m.block_load_offsets.push_back(static_cast<uint32_t>(m.block_load_clusters.size()));
  }
}

}  // namespace

template <typename Real>
SolverModel<Real>::SolverModel(const TreeModel& t, const HsmOptions& o, const WindOptions& w, double dt, int n,
                               size_t block_memberships)
    : tree(t), options(o), wind(w), frame_dt(dt), substeps(n), h(dt / n), V(t.vertex_count()), C(t.cluster_count()),
      M(t.membership_count()), L(t.leaf_count()), I(0), detach_enabled(o.leaf_detach_force > 0 && t.leaf_count() > 0),
      beam(o.global_matching), kick(beam && o.stiffness == StiffnessMode::kPhysical),
      store_drag_force(detach_enabled || beam),
      parallel(t.membership_count() >= kParallelMemberships),
      rotation_newton_stop(o.particles == ParticleMode::kSamples ? kNewtonStopSamples : kNewtonStopRoundOff),
      rotation_series_turns(o.particles == ParticleMode::kSamples),
      quick_chain(o.particles == ParticleMode::kSamples),
      lane_frames(o.particles == ParticleMode::kSamples) {
  if (!(dt > 0) || n < 1) throw InputError("simulator: frame_dt must be > 0 and substeps >= 1");
  const double extent = V ? (t.rest_positions.rowwise().maxCoeff() - t.rest_positions.rowwise().minCoeff()).maxCoeff() : 0.0;
  chain = build_bar_chain(t, o);
  const double size = std::max(extent, tree_reach(t, chain));
  const bool anchored = std::any_of(t.vertex_anchored.begin(), t.vertex_anchored.end(), [](auto a) { return a != 0; });
  runaway_distance2 = anchored && size > 0 ? std::pow(kRunawaySizes * size, 2) : std::numeric_limits<double>::infinity();
  Attachment<Real>& a = all_attached;
  precompute_members(*this, a);
  precompute_pins(*this, a);
  precompute_match_work(*this, a);
  for (size_t c = 0; c < C; ++c) rebuild_cluster_rest(*this, a, static_cast<uint32_t>(c));
  const StepRates rates = compute_step_rates(tree, options, chain, h);  // before the leaves join the chain
  cluster_alpha = rates.cluster_alpha;
  // The floor's pull and the chain's statics describe one limb (docs/solver.md, "The floor").
  if (std::any_of(rates.cluster_compliance_share.begin(), rates.cluster_compliance_share.end(), [](double s) { return s < 1; }))
    chain = build_bar_chain(t, o, rates.cluster_compliance_share);
  for (size_t c = 0; c < C; ++c) chain.cluster_compliance[c] *= rates.cluster_compliance_share[c];
  a.vertex_global.assign(rates.vertex_global.begin(), rates.vertex_global.end());
  a.vertex_half_damping.resize(V);
  a.vertex_kick_scale.resize(V);
  // The kick is scaled by sinh(x)/x before the second half step damps it by e^-x (x = zeta w h):
  // together (1 - e^-2x) / (2x), the creep of an overdamped limb. Past x = 40 each factor alone
  // would leave float (e^40 = 2e17, e^-88 underflows), so the half step stays e^-40 (the velocity
  // is gone either way) and the scale e^40 / (2x) keeps their product 1 / (2x), its value there.
  constexpr double kMostHalfStepExponent = 40;
  for (size_t v = 0; v < V; ++v) {
    const double x = rates.vertex_damping_exponent[v];
    if (!(x > kMostHalfStepExponent)) {
      const double damping = std::exp(-2 * x), exponent = -0.5 * std::log(damping);
      a.vertex_half_damping[v] = static_cast<Real>(std::sqrt(damping));
      a.vertex_kick_scale[v] =
          static_cast<Real>(exponent < 1e-4 ? 1 + exponent * exponent / 6 : std::sinh(exponent) / exponent);
    } else {
      a.vertex_half_damping[v] = static_cast<Real>(std::exp(-kMostHalfStepExponent));
      a.vertex_kick_scale[v] = static_cast<Real>(std::exp(kMostHalfStepExponent) / (2 * x));
    }
  }
  precompute_drag(*this, w);
  precompute_beam(*this, w);
  precompute_islands(*this);
  a.cluster_flying.assign(C, 0);
  a.cluster_released.assign(C, 0);
  a.vertex_flying.assign(V, 0);
  a.leaf_attached.assign(L, 1);
  sum_drag_areas(*this, a);
  precompute_blocks(*this, block_memberships);
  // Spatial phases of the wind at the rest centres: the tree moves little against the length
  // scales of the eddies and gusts, so they are evaluated once (flying leaves use their centre).
  const size_t P = size_t(wind.phase_count());
  cluster_phase_sin.resize(C * P);
  cluster_phase_cos.resize(C * P);
  for (size_t c = 0; c < C; ++c)
    wind.spatial_phases(a.cluster_rest_centre.col(c), &cluster_phase_sin[c * P], &cluster_phase_cos[c * P]);
}

// Weights are vertex masses; a cluster without mass (all members anchored or massless)
// falls back to equal weights, so its shape is still defined.
template <typename Real>
void rebuild_cluster_rest(const SolverModel<Real>& model, Attachment<Real>& a, uint32_t c) {
  const TreeModel& tree = model.tree;
  const uint32_t begin = tree.cluster_offsets[c], end = tree.cluster_offsets[c + 1];
  double total = 0;
  for (uint32_t s = begin; s < end; ++s)
    if (a.member_in_fit[s]) total += tree.vertex_mass[tree.cluster_members[s]];
  const bool uniform = !(total > 0);
  auto weight = [&](uint32_t s) {
    return !a.member_in_fit[s] ? 0.0 : uniform ? 1.0 : tree.vertex_mass[tree.cluster_members[s]];
  };
  if (uniform) total = 0;
  if (uniform)
    for (uint32_t s = begin; s < end; ++s) total += weight(s);
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (uint32_t s = begin; s < end; ++s)
    centre += (weight(s) / total) * tree.rest_positions.col(tree.cluster_members[s]);
  a.cluster_rest_centre.col(c) = centre;
  for (uint32_t s = begin; s < end; ++s) {
    const Eigen::Vector3d exact = a.member_active[s]
                                      ? Eigen::Vector3d(tree.rest_positions.col(tree.cluster_members[s]) - centre)
                                      : Eigen::Vector3d::Zero();
    a.member_offset.row(s) = exact.transpose().template cast<Real>();
    a.member_centre_weight[s] = static_cast<Real>(total > 0 ? weight(s) / total : 0.0);
  }
  const Eigen::Vector3d point =
      a.cluster_pin_slot[c] == kNone
          ? Eigen::Vector3d::Zero()
          : Eigen::Vector3d(a.member_offset.row(model.cluster_pin_own_slot[c]).transpose().template cast<double>());
  a.cluster_match_point.col(c) = point;
  // The sums below are taken over the stored (Real) q and weights, the values the step reads.
  double spread = 0;  // sum (w / sum w) |q - o|^2, m^2
  Eigen::Vector3d offset_sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d moment = Eigen::Matrix3d::Zero();
  for (uint32_t s = begin; s < end; ++s) {
    const double share = a.member_centre_weight[s];
    const Eigen::Vector3d q = a.member_offset.row(s).transpose().template cast<double>() - point;
    spread += share * q.squaredNorm();
    offset_sum += share * q;
    // Each entry as w (q_i q_j): exactly symmetric, so R = I exactly at the rest pose.
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) moment(i, j) += share * (q[i] * q[j]);
  }
  // A single-point cluster has no shape: its A_pq is 0 and the rotation keeps its warm start.
  const double scale = spread > 0 ? 1.0 / spread : 0.0;
  a.cluster_match_scale[c] = scale;
  moment *= scale;
  a.cluster_offset_sum.col(c) = scale * offset_sum;
  Eigen::Map<Eigen::Matrix3d>(&a.cluster_rest_moment(0, c)) = moment;
}

template <typename Real>
StepScratch<Real>::StepScratch(const SolverModel<Real>& m) {
  member_correction.setZero(m.correction_rows, 3);
  cluster_air.setZero(m.C, 3);
  cluster_rotation_matrix.setZero(9, m.C);
  cluster_load.setZero(3, m.C);
  cluster_moment.setZero(3, m.C);
  cluster_static_rotation.setZero(9, m.C);
  cluster_static_joint.setZero(3, m.C);
  cluster_pose.setZero(16, m.C);
  vertex_drag_damping.assign(m.V, Real(0));
  cluster_damping.assign(m.C, 0);
  cluster_damping_moment.setZero(3, m.C);
  cluster_damping_path.setZero(3, m.C);
  cluster_damping_lever.assign(m.C, 0);
  island_fell_asleep.assign(m.I, 0);
}

template struct SolverModel<float>;
template struct SolverModel<double>;
template struct StepScratch<float>;
template struct StepScratch<double>;
template void rebuild_cluster_rest(const SolverModel<float>&, Attachment<float>&, uint32_t);
template void rebuild_cluster_rest(const SolverModel<double>&, Attachment<double>&, uint32_t);

}  // namespace treeanim
