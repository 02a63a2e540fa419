#pragma once
// The tree as a bar chain (docs/solver.md, "Bending"): rigid clusters joined by rotational
// springs at their bases, Hencky's discrete Euler-Bernoulli beam. The solver pulls every
// vertex toward the chain's static deflection under the step's drag (beam_statics.cpp); the
// limbs sway at the chain's own first frequency.
#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "sim/sim_options.h"
#include "tree/tree_model.h"

namespace treeanim {

struct BarChain {
  Eigen::Matrix3Xd cluster_joint;          // (3 x C) m, rest point the cluster turns about: its base (a leaf: its shared vertex)
  std::vector<double> cluster_compliance;  // (C) rad/(N m) of the cluster's joint; 0 for leaves (set by the solver)
  // (C) rad, the joint's largest turn: where the wood at its surface reaches the yield strain,
  // at most a quarter turn (a leaf: a quarter turn, set by the solver). Beyond it the joint turns no further, as a
  // plastic hinge would: a gale folds a limb as far as wood bends, not round in circles.
  std::vector<double> cluster_max_turn;
  // The cluster tree cut for the chain's two walks (beam_statics.cpp), so that threads walk
  // disjoint limbs: the trunk (the clusters nearest the roots and the roots of the limbs that
  // hang from them, ascending) is walked by one thread, the rest in groups of whole limbs
  // below those roots (each group ascending) in parallel. A parent sums its children in the
  // same order whatever the cut or the threads, so the walks' results do not depend on them.
  std::vector<uint32_t> walk_trunk;
  std::vector<uint32_t> walk_group_offsets;  // (groups + 1) into walk_groups
  std::vector<uint32_t> walk_groups;
};

// Tree model + options (Young's modulus, yield strain, root flexibility) => the joints and the
// branch joints' compliances and largest turns. A cluster's flexibility L / (E I) is split
// between the joints at its two ends (the trapezoidal rule, second order in the cluster
// length): a joint that continues its parent's axis has half of each, a lateral's base half of
// its own, and the root half of its own plus the root plate's, root_flexibility H / (E I) for a
// tree H tall (the soil turns the stem's base, up to the stem's own largest turn). The yield
// moment of a cluster of radius r is strain E pi r^3 / 4. `stiffened` (C, or empty: all 1) scales
// each joint's compliance, root plate included, at the same yield moment
// (StepRates::cluster_compliance_share: the limb-frequency floor).
BarChain build_bar_chain(const TreeModel& model, const HsmOptions& options, std::span<const double> stiffened = {});

// Tree model + chain => the tree's reach (m): the longest path from a root cluster's joint to a
// vertex along the chain of joints. No connected pose moves a vertex farther than twice
// that from rest.
double tree_reach(const TreeModel& model, const BarChain& chain);

// Tree model + chain => per cluster (C), rad/s, the first frequency of the limb hanging from
// its joint, clamped there: Rayleigh's quotient w^2 = sum(m g.u) / sum(m |u|^2) over the limb's
// vertices for its static deflection u under its own weight turned sideways (the mean over two
// horizontal directions). Infinite for a limb that does not bend (no compliance or no mass).
// Up to `most_walked` vertex-joint pairs (each vertex times its depth in the cluster tree) the
// sums are taken per pair, as every bake always took them; past that, from each limb's mass
// moments in work linear in the tree, the same sums but for round-off: a single axis of 16,000
// clusters took 5 minutes per pair (docs/solver.md, "Stiffness").
constexpr size_t kMostWalkedLimbPairs = size_t(1) << 24;
std::vector<double> limb_frequencies(const TreeModel& model, const BarChain& chain,
                                     size_t most_walked = kMostWalkedLimbPairs);

}  // namespace treeanim
