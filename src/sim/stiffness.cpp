#include "sim/stiffness.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "common/errors.h"
#include "sim/bar_chain.h"

namespace treeanim {

namespace {

// First root of the clamped-free beam equation cos(b)cosh(b) = -1: w1 = b^2 sqrt(EI / (mu L^4)).
constexpr double kCantileverRoot = 1.8751040687119611;

// Cantilever of radius r (m), length L (m), mass m (kg) => first bending frequency (rad/s).
// A solid wood cylinder: I = pi r^4 / 4; mass per length m / L.
double cantilever_frequency(double E, double r, double L, double m) {
  if (!(r > 0 && L > 0 && m > 0)) return 0;
  const double I = std::numbers::pi * r * r * r * r / 4;
  return kCantileverRoot * kCantileverRoot * std::sqrt(E * I / (m * L * L * L));
}

// cluster_parent => clusters ordered parents first (depth ascending, then index).
std::vector<uint32_t> parents_first(const TreeModel& model) {
  const size_t C = model.cluster_count();
  std::vector<int> depth(C, -1);
  for (size_t c = 0; c < C; ++c) {
    // Walk up to a known depth, then unwind; a walk longer than C means a cycle.
    size_t steps = 0;
    int32_t a = static_cast<int32_t>(c);
    while (a >= 0 && depth[a] < 0) {
      a = model.cluster_parent[a];
      if (++steps > C) throw InputError("tree model: cluster_parent contains a cycle");
    }
    const int base = a >= 0 ? depth[a] : -1;
    std::vector<int32_t> chain;
    for (int32_t b = static_cast<int32_t>(c); b != a; b = model.cluster_parent[b]) chain.push_back(b);
    for (size_t i = chain.size(); i-- > 0;) depth[chain[i]] = base + int(chain.size() - i);
  }
  std::vector<uint32_t> order(C);
  for (size_t c = 0; c < C; ++c) order[c] = static_cast<uint32_t>(c);
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return depth[a] < depth[b]; });
  return order;
}

// Physical mode: segment (local) and limb frequencies of every cluster (docs/solver.md).
void physical_frequencies(const TreeModel& model, const HsmOptions& options, const BarChain& chain, StepRates& rates) {
  const size_t C = model.cluster_count();
  const double E = options.youngs_modulus;
  // Each vertex's mass is shared among its clusters, so subtree sums count it once.
  std::vector<double> own_mass(C, 0);
  for (size_t c = 0; c < C; ++c)
    for (uint32_t m = model.cluster_offsets[c]; m < model.cluster_offsets[c + 1]; ++m) {
      const uint32_t v = model.cluster_members[m];
      const uint32_t k = model.vertex_cluster_offsets[v + 1] - model.vertex_cluster_offsets[v];
      if (!model.vertex_anchored[v]) own_mass[c] += model.vertex_mass[v] / k;
    }
  const std::vector<uint32_t> order = parents_first(model);
  // The limb hanging from each cluster: its first frequency as a bar chain (Rayleigh), so
  // that taper, branching and the crown's mass, leaves included, set it as they set a tree's.
  const std::vector<double> limb = limb_frequencies(model, chain);
  // Parents before children: a cluster sways at most at the frequency of the softest limb
  // between it and the ground (a twig on a swaying bough moves with the bough).
  rates.cluster_frequency.assign(C, 0);
  rates.cluster_limb_frequency.assign(C, 0);
  rates.cluster_compliance_share.assign(C, 1);
  for (uint32_t c : order) {
    const int32_t p = model.cluster_parent[c];
    const double parent = p >= 0 ? rates.cluster_limb_frequency[p] : std::numeric_limits<double>::infinity();
    if (model.cluster_kind[c] == kClusterLeaf) {
      rates.cluster_limb_frequency[c] = std::isfinite(parent) ? parent : 0;
      continue;
    }
    rates.cluster_frequency[c] = cantilever_frequency(E, model.cluster_radius[c], model.cluster_length[c], own_mass[c]);
    rates.cluster_limb_frequency[c] = std::min(parent, limb[c]);
    // The floor stiffens a limb softer than it: its joint takes (w_limb / floor)^2 of its
    // compliance, so that the limb the goal bends sways at the floor the pull is given.
    const double floor = options.min_limb_frequency;
    if (limb[c] < floor) rates.cluster_compliance_share[c] = (limb[c] / floor) * (limb[c] / floor);
  }
}

}  // namespace

double global_rate(double omega, double h) {
  const double wh = omega * h;
  return wh < std::numbers::pi / 3 ? 2 * (1 - std::cos(wh)) : 1.0;
}

double local_rate(double omega, double h) {
  const double wh = omega * h;
  return wh < std::numbers::pi / 2 ? std::sin(wh) * std::sin(wh) : 1.0;
}

double global_frequency(double rate, double h) { return std::acos(1 - std::clamp(rate, 0.0, 4.0) / 2) / h; }

double local_frequency(double rate, double h) { return std::asin(std::sqrt(std::clamp(rate, 0.0, 1.0))) / h; }

StepRates compute_step_rates(const TreeModel& model, const HsmOptions& options, double h) {
  return compute_step_rates(model, options, build_bar_chain(model, options), h);
}

StepRates compute_step_rates(const TreeModel& model, const HsmOptions& options, const BarChain& chain, double h) {
  const size_t C = model.cluster_count(), V = model.vertex_count();
  StepRates rates;
  rates.cluster_alpha.assign(C, 0);
  std::vector<double> cluster_global(C, 0);  // per-step global rate of each cluster's vertices
  std::vector<double> cluster_damping_frequency(C, 0);
  size_t branches = 0, capped = 0;
  if (options.stiffness == StiffnessMode::kPhysical) {
    physical_frequencies(model, options, chain, rates);
    for (size_t c = 0; c < C; ++c) {
      const bool leaf = model.cluster_kind[c] == kClusterLeaf;
      // A branch cluster without geometry (zero radius, length or mass) has no finite
      // frequency: it gets the stiffest rate, like an unresolved one.
      // Segment frequencies of real wood are far above what a step resolves (a 0.5 m
      // segment of a 10 cm branch: ~2000 rad/s), and alpha saturates at 1 there, which would
      // make the tree stiffer with every added substep. Frequencies are therefore capped at
      // max_frequency, a property of the scene, not of the step (docs/solver.md).
      const double w_local = std::min(rates.cluster_frequency[c], options.max_frequency);
      // With the beam (the global term on), a branch's local term is a kick of the positions it
      // matched, as the global term is: 2(1 - cos wh) keeps w exact and adds no numerical
      // damping (docs/solver.md, "One step"); leaves keep the projection, rigid at leaf_alpha 1.
      const double shape_rate = options.global_matching ? global_rate(w_local, h) : local_rate(w_local, h);
      rates.cluster_alpha[c] = leaf ? options.leaf_alpha : w_local > 0 ? shape_rate : 1.0;
      if (!leaf) {
        ++branches;
        capped += rates.cluster_alpha[c] == 1.0;
      }
      // The limb (global) frequency has its own, lower cap: measured against a 256-substep
      // reference (scripts/bench-accuracy), limb modes above ~1.3 Hz are what a coarse step
      // resolves worst (measured at 16 substeps; the default is 2), while the local cap holds
      // branch shapes in a gale. And a floor, the bottom of the sway band of trees (0.2 Hz):
      // the beam model gives a limb of vanishing radius, or a zig-zag bush taken as a straight
      // beam of its longest path, a frequency near 0, and nothing then holds it in a gale
      // (docs/benchmarks.md, limit B).
      const double w = std::min(std::max(rates.cluster_limb_frequency[c], options.min_limb_frequency),
                                options.max_limb_frequency);
      cluster_global[c] = global_rate(std::sqrt(options.global_scale) * w, h);
      cluster_damping_frequency[c] = w;
    }
  } else {
    rates.cluster_frequency.assign(C, 0);
    rates.cluster_limb_frequency.assign(C, 0);
    rates.cluster_compliance_share.assign(C, 1);
    for (size_t c = 0; c < C; ++c) {
      const bool leaf = model.cluster_kind[c] == kClusterLeaf;
      rates.cluster_alpha[c] = leaf ? options.leaf_alpha : options.alpha;
      cluster_global[c] = options.k_d;
      // The frequency the per-step rates stand for at this h: of the global term when it is
      // on, else of the local term.
      cluster_damping_frequency[c] = options.global_matching && options.k_d > 0
                                         ? global_frequency(options.k_d, h)
                                         : local_frequency(rates.cluster_alpha[c], h);
    }
  }
  rates.capped_fraction = branches ? double(capped) / double(branches) : 0;

  // Per vertex: the mean over its clusters, in membership order (deterministic).
  rates.vertex_global.assign(V, 0);
  rates.vertex_damping_exponent.assign(V, 0);
  for (size_t v = 0; v < V; ++v) {
    const uint32_t begin = model.vertex_cluster_offsets[v], end = model.vertex_cluster_offsets[v + 1];
    if (model.vertex_anchored[v] || begin == end) continue;
    double global = 0, omega = 0;
    for (uint32_t s = begin; s < end; ++s) {
      const uint32_t c = model.member_cluster[model.vertex_memberships[s]];
      global += cluster_global[c];
      omega += cluster_damping_frequency[c];
    }
    const double k = end - begin;
    rates.vertex_global[v] = options.global_matching ? global / k : 0;
    rates.vertex_damping_exponent[v] = options.damping_ratio * (omega / k) * h;
  }
  return rates;
}

}  // namespace treeanim
