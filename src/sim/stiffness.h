#pragma once
// Stiffness and damping: options + tree geometry => the solver's per-step rates
// (docs/solver.md, "Stiffness" and "Damping").
#include <vector>

#include "sim/bar_chain.h"
#include "sim/sim_options.h"
#include "tree/tree_model.h"

namespace treeanim {

struct StepRates {
  std::vector<double> cluster_alpha;          // (C) local shape-matching rate per step, [0, 1]
  std::vector<double> cluster_frequency;      // (C) rad/s, local (segment) frequency; 0 in per-step mode
  std::vector<double> cluster_limb_frequency; // (C) rad/s, frequency of the softest limb holding the cluster
  // (C) factor on the cluster's joint compliance: (w_limb / min_limb_frequency)^2 for a branch
  // cluster whose own limb sways below the floor, else 1; the pull K = w^2 the floor raises and
  // the chain's statics then describe one limb (docs/solver.md, "The floor")
  std::vector<double> cluster_compliance_share;
  std::vector<double> vertex_global;          // (V) global (Eq. 8) rate per step; 0 when off or anchored
  std::vector<double> vertex_damping_exponent;  // (V) x = zeta w h: the velocity's factor per step is exp(-2x)
  double capped_fraction = 0;                 // share of branch clusters at alpha = 1 (a frequency the step does not resolve, or none finite)
};

// Natural angular frequency w (rad/s) and step h (s) => per-step rate of the global term
// (Eq. 8, applied to x(t) before the positions are predicted): 2(1 - cos wh), which keeps w
// exact for one vertex at any h; 1 when wh >= pi/3 (no overshoot: w is not resolved by h).
double global_rate(double omega, double h);
// w, h => per-step rate of the local term (Eq. 7 with the goals of the predicted positions):
// sin^2(wh), which keeps w exact for one vertex; 1 when wh >= pi/2 (docs/solver.md).
double local_rate(double omega, double h);
// Inverses: per-step rate r, step h => the angular frequency it stands for (rad/s).
double global_frequency(double rate, double h);
double local_frequency(double rate, double h);

// Model (geometry, masses) + options + its bar chain (build_bar_chain) + step h => every
// per-step rate of the solver.
StepRates compute_step_rates(const TreeModel& model, const HsmOptions& options, const BarChain& chain, double h);
// The same with the model's chain built here.
StepRates compute_step_rates(const TreeModel& model, const HsmOptions& options, double h);

}  // namespace treeanim
