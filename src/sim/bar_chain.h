#pragma once
// The tree as a bar chain (docs/solver.md, "Bending"): rigid clusters joined by rotational
// springs at their bases, Hencky's discrete Euler-Bernoulli beam. The solver pulls every
// vertex toward the chain's static deflection under the step's drag (beam_statics.cpp); the
// limbs sway at the chain's own first frequency.
#include <Eigen/Core>
#include <vector>

#include "tree/tree_model.h"

namespace treeanim {

struct BarChain {
  Eigen::Matrix3Xd cluster_joint;          // (3 x C) m, rest point the cluster turns about: its base (a leaf: its shared vertex)
  std::vector<double> cluster_compliance;  // (C) rad/(N m) of the cluster's joint; 0 for leaves (set by the solver)
};

// Tree model + Young's modulus (Pa) => the joints and the branch joints' compliances. A
// cluster's flexibility L / (E I) is split between the joints at its two ends (the
// trapezoidal rule, second order in the cluster length): a joint that continues its parent's
// axis has half of each, a lateral's base or the clamped root half of its own.
BarChain build_bar_chain(const TreeModel& model, double youngs_modulus);

// Tree model + chain => per cluster (C), rad/s, the first frequency of the limb hanging from
// its joint, clamped there: Rayleigh's quotient w^2 = sum(m g.u) / sum(m |u|^2) over the limb's
// vertices for its static deflection u under its own weight turned sideways (the mean over two
// horizontal directions). Infinite for a limb that does not bend (no compliance or no mass).
std::vector<double> limb_frequencies(const TreeModel& model, const BarChain& chain);

}  // namespace treeanim
