#pragma once
// The solver's data by lifetime (docs/design.md, "The solver's data"): SolverModel, built
// once from the TreeModel and the options and read-only afterwards; Attachment, the rest data
// that the attached leaves decide (a function of the model and SimState::leaf_attached);
// StepScratch, per-step buffers (Box2D's b2StepContext). The state is SimState. Every type
// is a template on `Real`, what the step state is stored in (docs/solver.md, "Precision").
#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "sim/bar_chain.h"
#include "sim/sim_options.h"
#include "sim/sim_state.h"
#include "sim/vertex_run.h"
#include "sim/wind.h"
#include "tree/tree_model.h"

namespace treeanim {

constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();
constexpr long long kNoVolumeFrame = std::numeric_limits<long long>::min();  // StepScratch::volume_sampled: none

// Memberships from which the solver's loops run on several threads: below, the fork/join
// costs more than the work (results are identical either way).
constexpr size_t kParallelMemberships = 4096;

// Arrays of 3-vectors that the step reads or writes are (n x 3): a column per axis
// (structure of arrays), so that the vertex pass and the goal writes run on SIMD packets.
template <typename Real>
using Rows3 = Eigen::Matrix<Real, Eigen::Dynamic, 3>;

// An attached vertex farther from rest than this many times the tree's size stops the bake
// (SolverModel::runaway_distance2): twice is the farthest a connected rigid pose reaches (a
// half turn at the root), the rest a margin for a swing past it and the clusters' stretch.
constexpr double kRunawaySizes = 2.5;

// Memberships [begin, end) of one cluster whose corrections go to consecutive rows of
// StepScratch::member_correction from `row` (SolverModel::correction_runs). Below V the row is
// the member vertex itself.
struct CorrectionRun {
  uint32_t begin, end, row;
};

// Vertices [begin, end): a run of consecutive vertices one pass takes as one range.
struct VertexSegment {
  uint32_t begin, end;
};

// What the leaves' attachment decides: the clusters' rest data for the members they keep,
// and which vertices fly. With every leaf attached it is precomputed in the SolverModel;
// detachment.cpp changes it when a leaf detaches, and rebuilds it from the model for a state
// whose leaf_attached differs (a checkpoint): the result depends on the set of detached
// leaves alone, never on the order in which they detached.
template <typename Real>
struct Attachment {
  std::vector<uint8_t> leaf_attached;      // (L) the flags this was built for
  // --- per membership (M), in cluster_members order ---
  std::vector<uint8_t> member_active;      // (M) 0 once the membership was released (detached leaf)
  // (M) 1 where the member's mass counts in its cluster's fit: active, and not an attached
  // leaf's shared vertex in its branch (docs/solver.md, "Leaves")
  std::vector<uint8_t> member_in_fit;
  Rows3<Real> member_offset;               // (M x 3) m, rest offset q = x0 - t0 from the cluster's rest centre
  // (M) w / sum(w): mass share in the cluster's centre; times cluster_match_scale, the weight
  // of the member in A_pq
  std::vector<Real> member_centre_weight;
  // --- per cluster (C) ---
  Eigen::Matrix3Xd cluster_rest_centre;    // (3 x C) m, mass-weighted rest centre t0
  // (3 x C) m, rest position minus t0 of the point the fit rotates about, o: 0 (the centre)
  // but for an attached leaf, which turns about its shared vertex
  Eigen::Matrix3Xd cluster_match_point;
  // (C) 1/m^2, 1 / sum((w / sum w) |q - o|^2): A_pq = sum s d (q - o)^T with s = (w / sum w)
  // times it is of order 1 for any cluster size
  std::vector<double> cluster_match_scale;
  Eigen::Matrix3Xd cluster_offset_sum;     // (3 x C) 1/m, sum of s (q - o) over the members (o = 0: round-off only)
  Eigen::Matrix<double, 9, Eigen::Dynamic> cluster_rest_moment;  // (9 x C) sum s (q - o)(q - o)^T, column-major: A_pq at rest
  std::vector<uint32_t> cluster_pin_slot;  // (C) attached leaf: membership of its shared vertex in the branch; else kNone
  std::vector<uint8_t> cluster_flying;     // (C) 1: a detached leaf (always awake)
  // (C) 1: some membership of the cluster was released. Until then (every cluster until a leaf
  // detaches) the loops over its members read no byte flag: each would make GCC vectorise the
  // loop 32 floats at a time, more than a cluster holds, or cost a load and a conversion a member.
  std::vector<uint8_t> cluster_released;
  // The drag per unit |u| u of the cluster and everything beyond it (0.5 rho Cd A, kg/m) and
  // its moment about the cluster's joint (3 x C, kg), with rest arms: the load of the air a
  // step leaves out (docs/solver.md, "What a step cannot resolve"), fixed by the attachment.
  std::vector<double> cluster_drag_area;
  Eigen::Matrix3Xd cluster_drag_arm;
  // --- per vertex (V) ---
  std::vector<Real> vertex_global;         // (V) global rate per step (0: off, anchored, flying)
  // (V) velocity factor per half step of the limb's structural damping (the step's damping is
  // two); 1 on a flying leaf, whose rigid flight no limb damps
  std::vector<Real> vertex_half_damping;
  // (V) what the kick between those halves is scaled by, sinh(x) / x with e^-x the half step's
  // factor: the damped step then moves a vertex under a steady force as far as the force and
  // the damping do together, (1 - e^-2x) / (2x) of the undamped kick (docs/solver.md,
  // "Damping"); 1 where nothing damps
  std::vector<Real> vertex_kick_scale;
  std::vector<Real> vertex_inv_count;      // (V) 1 / number of active memberships (0: none)
  std::vector<uint32_t> vertex_air_cluster;// (V) the cluster whose air velocity the vertex feels
  std::vector<uint8_t> vertex_flying;      // (V) 1: on a detached leaf (gravity on, global off)
};

// A leaf's card: vertices vertex..vertex + 3 in `cluster` at memberships slot..slot + 3, and
// the first, the leaf's shared vertex, in its branch `pin_cluster` at `pin_slot` before that.
struct LeafCard {
  uint32_t vertex, cluster, slot, pin_cluster, pin_slot;
};

// Everything the step needs that never changes during a bake.
template <typename Real>
struct SolverModel {
  const TreeModel& tree;                   // must outlive the solver
  HsmOptions options;
  WindField wind;
  double frame_dt;                         // s
  int substeps;
  double h;                                // s, one substep
  // m^2: (kRunawaySizes x the tree's size)^2, its size the larger of the rest mesh's extent and
  // its reach along the branches (tree_reach). An attached vertex of an anchored tree farther
  // than that from rest means the tree came apart (docs/solver.md, "Runaway").
  // Infinite without anchors (a free body may travel) and for a single-point model.
  double runaway_distance2;
  size_t V, C, M, L, I;
  bool detach_enabled;                     // leaf_detach_force > 0 and the tree has leaves
  // The global term on: it pulls toward the static deflection of the clusters as a beam
  // (beam_statics.cpp), and the drag acts on attached vertices only through it.
  bool beam;
  // Physical stiffness with the beam: the global term, and a branch's local term, are kicks
  // of the step (second order); otherwise both move the predicted positions (the paper's Eq. 7, 8).
  bool kick;
  bool store_drag_force;                   // the prediction keeps each vertex's drag (detachment, beam)
  bool parallel;                           // at least kParallelMemberships: the loops run on several threads
  // hsm.particles "samples", whose clusters' fixed costs are its step's, takes cheaper choices
  // of the same accuracy (docs/solver.md, "Particles"); "vertices" keeps the paper's set-up byte for byte.
  double rotation_newton_stop;             // rad, the Newton step that ends a rotation's iterations (rotation.h)
  bool rotation_series_turns;              // each of those steps turns by the series of its sine and cosine (rotation.h)
  // The chain's turns by their series (beam_statics.cpp, series_rotation), and their unscented
  // mean in one cross product where no point reaches the yield turn (turn_joints_quickly)
  bool quick_chain;
  // The correction pass reads each vertex's cluster frame (air, R) per lane rather than once per
  // run of a cluster's vertices: a run of three or four samples is too short to fill a vector.
  bool lane_frames;
  std::vector<double> cluster_alpha;       // (C) local rate per step
  std::vector<uint32_t> cluster_island;    // (C) island id
  std::vector<uint32_t> cluster_pin_own_slot;  // (C) leaf pinned to a branch: membership of the shared vertex in the leaf
  // (C x P) spatial phases of the wind (turbulence modes, then gust waves) at t0: the air a
  // cluster feels is a function of its world position
  std::vector<double> cluster_phase_sin, cluster_phase_cos;
  std::vector<uint32_t> pinned_leaf_clusters;  // clusters of the leaves that start attached to a branch
  // (C + 1) prefix sums of each cluster's work in match_clusters' first pass, which its threads
  // split evenly (balanced_range): a cluster's memberships weigh less than its fit, and a pinned
  // leaf's fit comes after the pass
  std::vector<uint32_t> match_work_offsets;
  // (V) 1: a branch vertex with the beam, whose mean correction is a kick of the next step;
  // 0: a projection (leaves, the per_step stiffness)
  std::vector<uint8_t> vertex_shape_kick;
  std::vector<Real> vertex_drag;           // (V) 1/m, 0.5 rho Cd A / m: drag acceleration per (m/s)^2
  std::vector<Real> vertex_mass;           // (V) kg, the tree's masses rounded to Real, as the drag's force reads them
  BarChain chain;                          // the beam's joints and compliances (a leaf's: its petiole's)
  Rows3<Real> member_arm;                  // (M x 3) m, with the beam: x0 - the joint of the member's cluster
  // (M) the row of StepScratch::member_correction that a membership's correction is written
  // to: its vertex's own row v when it is the only membership of a free vertex (so the vertex
  // passes read it in order, not gathered), else a row of its own past V, in membership order
  std::vector<uint32_t> member_correction_row;
  size_t correction_rows;                  // V + the memberships with a row of their own
  // Those rows as runs, cluster c's in correction_runs[correction_run_offsets[c],
  // correction_run_offsets[c + 1]), so that the fit writes them as vectors, not scattered.
  std::vector<uint32_t> correction_run_offsets;
  std::vector<CorrectionRun> correction_runs;
  std::vector<uint32_t> shared_vertices;   // free vertices in two or more clusters, ascending
  // The rows of their memberships' corrections, in each vertex's order: those of
  // shared_vertices[i] are shared_correction_rows[shared_row_offsets[i], shared_row_offsets[i + 1])
  std::vector<uint32_t> shared_row_offsets, shared_correction_rows;
  // Runs of vertices in 1 to kMaxRunClusters clusters (and no leaf's shared vertex, whose
  // memberships may be released): consecutive vertices in the same clusters, in the same order,
  // with consecutive memberships in each, ascending. The goal writes take a run as one loop on
  // its clusters' values, read from this table in order (not through each vertex's memberships,
  // a chain of dependent loads per run).
  std::vector<VertexRun> vertex_runs;
  // The leaves whose four vertices are a card (every leaf of four vertices in either particle
  // mode), ascending: the goal writes take its vertices in one vector's lanes.
  std::vector<LeafCard> leaf_cards;
  // --- the step in cache blocks (cache_blocks.cpp; docs/solver.md, "Cache blocks") ---
  // B blocks of clusters of about the constructor's block_memberships memberships, each
  // predicted, matched, corrected and loaded in turn while its data is in cache; empty (the
  // separate passes of match_clusters and correct_and_predict) for block_memberships 0, a
  // tree of fewer than two blocks, or leaves that detach (a detachment falls between a step's
  // prediction and its match, which a block does at once).
  // Block b's clusters are block_clusters[block_cluster_offsets[b], [b + 1]): consecutive
  // branch clusters (and unpinned leaves), ascending, then the leaves pinned to them, ascending.
  std::vector<uint32_t> block_cluster_offsets, block_clusters;
  std::vector<uint32_t> block_membership_offsets;  // (B + 1) memberships before block b: threads take equal shares
  // The vertices whose clusters are all block b's, as segments: block_segments[block_segment_offsets[b],
  // [b + 1]); entry B: the border, vertices of clusters in two blocks (or in none), predicted
  // before the blocks and corrected after them.
  std::vector<uint32_t> block_segment_offsets;
  std::vector<VertexSegment> block_segments;
  // The clusters whose loads block b sums, those without a border vertex: block_load_clusters[
  // block_load_offsets[b], [b + 1]); entry B: the others, summed after the border's correction.
  std::vector<uint32_t> block_load_offsets, block_load_clusters;
  std::vector<uint32_t> vertex_island;     // (V) island id, kNone for anchored vertices
  // --- islands (I): clusters connected through shared non-anchored vertices ---
  std::vector<uint32_t> island_vertex_offsets;  // (I+1) CSR into island_vertices
  std::vector<uint32_t> island_vertices;        // non-anchored vertices, ascending per island

  Attachment<Real> all_attached;           // the rest data of the bake's start

  SolverModel(const TreeModel& tree, const HsmOptions& options, const WindOptions& wind, double frame_dt,
              int substeps, size_t block_memberships = 0);
};

// Per-step buffers: written before they are read within a step (no allocation in the step).
template <typename Real>
struct StepScratch {
  // (rows x 3) m: row v the mean correction of vertex v (0 for an anchor or a vertex in no
  // cluster), the others alpha_c (g - p) of the memberships that are not a vertex's only one
  // (SolverModel::member_correction_row), of the current step. A free vertex in one cluster
  // has its membership's correction written straight to its row; a shared vertex's row is
  // averaged from its memberships' rows before the vertex passes read it.
  Rows3<Real> member_correction;
  Rows3<Real> cluster_air;                 // (C x 3) m/s, air velocity at the cluster for the step being predicted
  Eigen::Matrix<double, 9, Eigen::Dynamic> cluster_rotation_matrix;  // (9 x C) R of this step's fit, column-major
  Eigen::Matrix3Xd cluster_load;           // (3 x C) N, drag on the cluster and everything beyond it
  Eigen::Matrix3Xd cluster_moment;         // (3 x C) N m, its moment about the cluster's joint
  Eigen::Matrix<double, 9, Eigen::Dynamic> cluster_static_rotation;  // (9 x C) the cluster's turn in the static deflection
  Eigen::Matrix3Xd cluster_static_joint;   // (3 x C) m, where its joint is in the static deflection
  // (16 x C) the deflected pose the goal writes read: R - I (column-major), the joint's move
  // (m), cluster_damping_path, cluster_damping_lever
  Eigen::Matrix<Real, 16, Eigen::Dynamic> cluster_pose;
  // --- the chain's aerodynamic damping (docs/solver.md, "Aerodynamic damping") ---
  std::vector<Real> vertex_drag_damping;   // (V) N s/m, D = 0.5 rho Cd A |air - v|: the drag per m/s of relative velocity
  std::vector<double> cluster_damping;     // (C) N s/m, sum of 2 D over the cluster and everything beyond it
  Eigen::Matrix3Xd cluster_damping_moment; // (3 x C) N s, sum of 2 D (x0 - joint) over the same vertices
  // (3 x C) s/m, sum over the joints from the root to the cluster's of compliance times damping moment
  Eigen::Matrix3Xd cluster_damping_path;
  std::vector<double> cluster_damping_lever;  // (C) s, the same joints' sum of compliance C_j S_j . (j_c - j_j)
  std::vector<uint8_t> island_fell_asleep; // (I) islands put to sleep at the end of this frame
  AirSample air;                           // the wind at the time being sampled
  // --- a wind volume (air.cpp): its frames around the time being sampled, and its velocity at
  // the clusters' rest centres in the two frames last sampled, kept while the frames are current ---
  VolumeInstant volume;
  std::array<long long, 2> volume_sampled{kNoVolumeFrame, kNoVolumeFrame};  // frames of volume_at_rest
  std::array<Eigen::Matrix3Xd, 2> volume_at_rest;     // (3 x C) m/s, at each cluster's rest centre
  std::array<std::vector<uint8_t>, 2> volume_inside;  // (C) 1: that centre is inside the frame's volume

  explicit StepScratch(const SolverModel<Real>& model);
};

// CSR offsets (n+1) + this thread's index and the thread count => the contiguous range of
// rows [begin, end) holding an equal share of the entries. Balances clusters of very
// different sizes (trunk rings, 4-vertex leaves); results never depend on the split.
inline std::pair<size_t, size_t> balanced_range(const std::vector<uint32_t>& offsets, int thread, int threads) {
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

// Cluster c, attachment, state => whether the cluster steps (a flying leaf always does).
template <typename Real>
inline bool cluster_awake(const SolverModel<Real>& model, const Attachment<Real>& attachment, const SimState& state,
                          size_t c) {
  return attachment.cluster_flying[c] || !state.island_asleep[model.cluster_island[c]];
}

// Active members of cluster c => its rest centre, rest offsets and normalised weights, and
// the rest moment about its match point (an attached leaf's shared vertex, else the centre).
template <typename Real>
void rebuild_cluster_rest(const SolverModel<Real>& model, Attachment<Real>& attachment, uint32_t c);

}  // namespace treeanim
