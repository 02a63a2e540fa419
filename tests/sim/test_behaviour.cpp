// Whole-bake behaviour on grown trees: coming to rest, thin versus thick branches, leaves
// detaching, sleeping, trees downwind of each other, thread-count determinism, convergence in
// the substep count.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <numbers>
#include <tuple>

#include "sim/simulator.h"
#include "sim/solver_model.h"
#include "sim/stiffness.h"
#include "correlation.h"
#include "grown_tree.h"
#include "sim_test_models.h"
#include "tip_motion.h"

namespace treeanim {
namespace {

using testing::grown_tree;
using testing::best_lag;
using testing::correlation;
using testing::gust_then_calm;

double max_displacement(const SimState& state, const TreeModel& model) {
  return (state.positions - model.rest_positions).colwise().norm().maxCoeff();
}

TEST(Behaviour, TreeComesToRestAfterTheWindStops) {
  // Documented in docs/solver.md ("Damping"): with the default damping a tree is within
  // 1 mm of its rest pose 10 s after the wind has stopped.
  const TreeModel model = grown_tree(5, 2, 4);
  HsmOptions options;
  options.sleep = false;
  Simulator sim(model, options, gust_then_calm(12, 3, 3.5), 1.0 / 24, 4);
  SimState state = sim.initial_state(0);
  double peak = 0;
  for (int f = 1; f <= 24 * 14; ++f) {
    sim.advance_frame(state, f);
    if (f <= 24 * 4) peak = std::max(peak, max_displacement(state, model));
  }
  EXPECT_GT(peak, 0.02);  // the wind did bend the tree
  EXPECT_LT(max_displacement(state, model), 1e-3);
  EXPECT_LT(state.velocities.colwise().norm().maxCoeff(), 1e-2);
}

TEST(Behaviour, ThinBranchesMoveMoreThanThickOnes) {
  const TreeModel model = grown_tree(6, 0, 2);
  WindOptions wind;
  wind.keys = {{0, 8, {1, 0, 0.3}, 2}};
  HsmOptions options;
  Simulator sim(model, options, wind, 1.0 / 24, 4);
  SimState state = sim.initial_state(0);
  const size_t C = model.cluster_count();
  std::vector<double> peak(C, 0);
  for (int f = 1; f <= 24 * 4; ++f) {
    sim.advance_frame(state, f);
    for (size_t c = 0; c < C; ++c)
      for (uint32_t s = model.cluster_offsets[c]; s < model.cluster_offsets[c + 1]; ++s) {
        const uint32_t v = model.cluster_members[s];
        peak[c] = std::max(peak[c], (state.positions.col(v) - model.rest_positions.col(v)).norm());
      }
  }
  // Branch clusters sorted by radius, split in about four classes, the clusters of one radius
  // (to the round-off of the grammar's float parameters) kept in one class: many have it, and
  // between two of them the order says nothing. The mean peak displacement of each class is
  // below the thinner class's.
  std::vector<size_t> branches;
  for (size_t c = 0; c < C; ++c)
    if (model.cluster_kind[c] == kClusterBranch) branches.push_back(c);
  std::sort(branches.begin(), branches.end(),
            [&](size_t a, size_t b) { return model.cluster_radius[a] < model.cluster_radius[b]; });
  ASSERT_GE(branches.size(), 40u);
  double previous = std::numeric_limits<double>::infinity();
  for (size_t k = 0, lo = 0; lo < branches.size(); ++k) {
    size_t hi = std::max(lo + 1, branches.size() * (k + 1) / 4);
    while (hi < branches.size() &&
           model.cluster_radius[branches[hi]] <= model.cluster_radius[branches[hi - 1]] * (1 + 1e-6))
      ++hi;
    double sum = 0;
    for (size_t i = lo; i < hi; ++i) sum += peak[branches[i]];
    const double mean = sum / double(hi - lo);
    EXPECT_LT(mean, previous) << "radius class " << k << " (radius up to " << model.cluster_radius[branches[hi - 1]]
                              << " m)";
    previous = mean;
    lo = hi;
  }
}

// Cluster c => the mass of its members that are not anchored (kg).
double free_cluster_mass(const TreeModel& model, size_t c) {
  double mass = 0;
  for (uint32_t s = model.cluster_offsets[c]; s < model.cluster_offsets[c + 1]; ++s)
    if (!model.vertex_anchored[model.cluster_members[s]]) mass += model.vertex_mass[model.cluster_members[s]];
  return mass;
}

TEST(Behaviour, ThickBranchesAreStifferAndHeavier) {
  const TreeModel model = grown_tree(6, 0, 2);
  const StepRates rates = compute_step_rates(model, HsmOptions{}, 1.0 / 96);
  // Parent clusters are thicker than their children: heavier per length, and the limb
  // holding a child sways no faster than the one holding its parent.
  size_t checked = 0;
  for (size_t c = 0; c < model.cluster_count(); ++c) {
    const int32_t p = model.cluster_parent[c];
    if (p < 0 || model.cluster_kind[c] != kClusterBranch) continue;
    EXPECT_LE(rates.cluster_limb_frequency[c], rates.cluster_limb_frequency[p]);
    if (model.cluster_radius[p] > 1.5 * model.cluster_radius[c]) {
      EXPECT_GT(free_cluster_mass(model, p) / model.cluster_length[p], free_cluster_mass(model, c) / model.cluster_length[c]);
      ++checked;
    }
  }
  EXPECT_GT(checked, 10u);
}

TEST(Behaviour, LimbFrequencyHasAFloor) {
  // Wood of 1 MPa gives every limb a frequency far below the sway band of trees; the floor
  // (min_limb_frequency) holds each moving vertex's global rate at that frequency's.
  const TreeModel model = grown_tree(6, 0, 2);
  const double h = 1.0 / 96;
  HsmOptions soft;
  soft.youngs_modulus = 1e6;
  const double floor_rate = global_rate(soft.min_limb_frequency, h);
  const std::vector<double> held = compute_step_rates(model, soft, h).vertex_global;
  soft.min_limb_frequency = 0;
  const std::vector<double> free = compute_step_rates(model, soft, h).vertex_global;
  size_t below = 0;
  for (size_t v = 0; v < model.vertex_count(); ++v) {
    if (model.vertex_anchored[v]) continue;
    EXPECT_GE(held[v], floor_rate * (1 - 1e-12)) << "vertex " << v;
    below += free[v] < floor_rate;
  }
  EXPECT_GT(below, model.vertex_count() / 2);
}

TEST(Behaviour, LimbFrequenciesFromMassMomentsAreThoseOfTheWalks) {
  // A tree past the walks' work (each vertex times its depth) takes Rayleigh's sums from its
  // limbs' mass moments: the same frequencies but for round-off, limb by limb, leaves included,
  // and along a single axis of 1,024 clusters (where its moments are long sums of differences).
  std::vector<TreeModel> models;
  for (const auto& [iterations, leaves, segments] : {std::tuple{6, 2, 2}, {7, 0, 1}, {5, 3, 4}})
    models.push_back(grown_tree(iterations, leaves, segments));
  LsystemOptions stem;
  stem.axiom = "F";
  stem.productions = {"F -> FF"};
  stem.iterations = 10;
  TreeOptions one_segment;
  one_segment.cluster.segments_per_cluster = 1;
  models.push_back(build_tree_model(grow_skeleton(stem, nullptr), one_segment));
  for (const TreeModel& model : models) {
    HsmOptions options;
    options.youngs_modulus = 2e8;
    const BarChain chain = build_bar_chain(model, options);
    const std::vector<double> walked = limb_frequencies(model, chain, SIZE_MAX);
    const std::vector<double> summed = limb_frequencies(model, chain, 0);
    ASSERT_EQ(walked.size(), model.cluster_count());
    size_t finite = 0;
    for (size_t c = 0; c < model.cluster_count(); ++c) {
      if (std::isinf(walked[c])) {
        EXPECT_TRUE(std::isinf(summed[c])) << "cluster " << c << ": " << summed[c];
        continue;
      }
      ++finite;
      EXPECT_NEAR(summed[c], walked[c], 1e-12 * walked[c]) << "cluster " << c << " of " << model.cluster_count();
    }
    EXPECT_GT(finite, model.cluster_count() / 4);
  }
}

TEST(Behaviour, TheFloorStiffensTheLimbsBelowIt) {
  // The floor raises a soft limb's pull K = w^2; its joints take (w_limb / floor)^2 of their
  // compliance, so that the limb the goal bends sways no faster than the floor and faster than
  // before, and the damping K G 2D stays the drag's own. Wood above the floor is left as it is.
  const TreeModel model = grown_tree(6, 0, 2);
  HsmOptions soft;
  soft.youngs_modulus = 1e6;
  const BarChain chain = build_bar_chain(model, soft);
  const std::vector<double> before = limb_frequencies(model, chain);
  const StepRates rates = compute_step_rates(model, soft, chain, 1.0 / 96);
  const BarChain stiff = build_bar_chain(model, soft, rates.cluster_compliance_share);
  const std::vector<double> after = limb_frequencies(model, stiff);
  const double floor = soft.min_limb_frequency;
  size_t below = 0;
  for (size_t c = 0; c < model.cluster_count(); ++c) {
    if (model.cluster_kind[c] != kClusterBranch || !(before[c] < floor)) {
      EXPECT_EQ(rates.cluster_compliance_share[c], 1.0) << "cluster " << c;
      continue;
    }
    ++below;
    EXPECT_DOUBLE_EQ(rates.cluster_compliance_share[c], before[c] * before[c] / (floor * floor)) << "cluster " << c;
    EXPECT_GT(after[c], before[c]) << "cluster " << c;
    EXPECT_LE(after[c], floor * (1 + 1e-9)) << "cluster " << c;
    // The joint turns less under the same moment, and reaches its yield turn at the same moment.
    const double share = rates.cluster_compliance_share[c];
    EXPECT_NEAR(stiff.cluster_compliance[c], share * chain.cluster_compliance[c], 1e-12 * chain.cluster_compliance[c]);
    if (chain.cluster_max_turn[c] < std::numbers::pi / 2) {
      EXPECT_NEAR(stiff.cluster_max_turn[c], share * chain.cluster_max_turn[c], 1e-12) << "cluster " << c;
    }
  }
  EXPECT_GT(below, 10u);  // the trunk and the boughs; the twigs' own limbs sway above the floor
  const StepRates wood = compute_step_rates(model, HsmOptions{}, 1.0 / 96);
  for (const double share : wood.cluster_compliance_share) EXPECT_EQ(share, 1.0);
}

TEST(Behaviour, DetachedLeavesFallAndNeverComeBack) {
  const TreeModel model = testing::small_tree(6);
  HsmOptions options;
  options.leaf_detach_force = 0.9;  // N: a 6 cm leaf lets go in the strongest gusts
  Simulator sim(model, options, gust_then_calm(20, 1.0, 1.2), 1.0 / 24, 4);
  SimState state = sim.initial_state(0);
  std::vector<uint8_t> attached = state.leaf_attached;
  std::vector<double> height_when_free(model.leaf_count(), 0);
  for (int f = 1; f <= 24 * 4; ++f) {
    sim.advance_frame(state, f);
    for (size_t l = 0; l < model.leaf_count(); ++l) {
      ASSERT_LE(state.leaf_attached[l], attached[l]) << "leaf " << l << " re-attached at frame " << f;
      if (attached[l] && !state.leaf_attached[l])
        height_when_free[l] = state.positions(1, model.leaf_attachment_vertex[l]);
    }
    attached = state.leaf_attached;
  }
  size_t detached = 0;
  for (size_t l = 0; l < model.leaf_count(); ++l) {
    if (state.leaf_attached[l]) continue;
    ++detached;
    // Three seconds after the gust a free leaf has fallen well below where it let go, and
    // far from its branch.
    const uint32_t v = model.leaf_attachment_vertex[l];
    EXPECT_LT(state.positions(1, v), height_when_free[l] - 1.0) << "leaf " << l;
    EXPECT_GT((state.positions.col(v) - model.rest_positions.col(v)).norm(), 1.0) << "leaf " << l;
    // Still a rigid leaf: its side keeps its length.
    const uint32_t c = model.leaf_cluster[l], a = model.cluster_members[model.cluster_offsets[c]],
                   b = model.cluster_members[model.cluster_offsets[c] + 1];
    EXPECT_NEAR((state.positions.col(a) - state.positions.col(b)).norm(),
                (model.rest_positions.col(a) - model.rest_positions.col(b)).norm(), 1e-3);
  }
  EXPECT_GT(detached, 0u);
  EXPECT_LT(detached, model.leaf_count());  // the weakest gusts leave some leaves on
}

// A flying leaf falls as gravity and drag say whatever the tree's structural damping: that
// damping belongs to a limb's bending (a limb of 300 rad/s at damping ratio 0.1 once held
// detached leaves still in mid-air). Every leaf lets go in the first steps, from rest, so what
// follows is free flight, but for the steps it rode its (damped) branch: 0.2 mm here, where
// the damping made a leaf fall nowhere.
TEST(Behaviour, AFlyingLeafFeelsNoLimbDamping) {
  const TreeModel model = testing::small_tree(6);
  auto fall = [&](double damping_ratio) {
    HsmOptions options;
    options.leaf_detach_force = 1e-9;  // N
    options.damping_ratio = damping_ratio;
    Simulator sim(model, options, gust_then_calm(3, 0.1, 0.2), 1.0 / 24, 4);
    SimState state = sim.initial_state(0);
    for (int f = 1; f <= 24; ++f) sim.advance_frame(state, f);
    for (uint8_t a : state.leaf_attached) EXPECT_EQ(a, 0);
    return state;
  };
  const SimState free = fall(0), damped = fall(5);
  for (size_t l = 0; l < model.leaf_count(); ++l) {
    const uint32_t c = model.leaf_cluster[l];
    for (uint32_t i = model.cluster_offsets[c]; i < model.cluster_offsets[c + 1]; ++i) {
      const uint32_t v = model.cluster_members[i];
      if (model.vertex_leaf[v] != static_cast<int32_t>(l)) continue;
      EXPECT_LT(free.positions(1, v), model.rest_positions(1, v) - 1.0) << "leaf " << l << " fell a second";
      EXPECT_NEAR((damped.positions.col(v) - free.positions.col(v)).norm(), 0, 1e-3) << "leaf " << l;
    }
  }
}

// A leaf drawn before any segment is anchored at its petiole, where it was drawn: held by the
// ground, it stays on and rigid in a gale that strips the leaves of the stem.
TEST(Behaviour, ALeafHeldByTheGroundNeverDetaches) {
  LsystemOptions lsystem;
  lsystem.axiom = "L(1)[+(90)L(1)]!(0.05)F(1)F(1)L(1)";
  lsystem.iterations = 0;
  const TreeModel model = build_tree_model(grow_skeleton(lsystem, nullptr), TreeOptions{});
  ASSERT_EQ(model.leaf_count(), 3u);
  HsmOptions options;
  options.leaf_detach_force = 1e-4;  // N
  Simulator sim(model, options, gust_then_calm(25, 2, 3), 1.0 / 24, 4);
  SimState state = sim.initial_state(0);
  for (int f = 1; f <= 48; ++f) sim.advance_frame(state, f);
  size_t grounded = 0;
  for (size_t l = 0; l < model.leaf_count(); ++l) {
    if (!model.vertex_anchored[model.leaf_attachment_vertex[l]]) {
      EXPECT_EQ(state.leaf_attached[l], 0) << "leaf " << l << " of the stem";
      continue;
    }
    ++grounded;
    EXPECT_EQ(state.leaf_attached[l], 1) << "leaf " << l;
    const uint32_t c = model.leaf_cluster[l];
    for (uint32_t i = model.cluster_offsets[c]; i < model.cluster_offsets[c + 1]; ++i)
      for (uint32_t j = model.cluster_offsets[c]; j < i; ++j) {
        const uint32_t a = model.cluster_members[i], b = model.cluster_members[j];
        EXPECT_NEAR((state.positions.col(a) - state.positions.col(b)).norm(),
                    (model.rest_positions.col(a) - model.rest_positions.col(b)).norm(), 1e-3)
            << "leaf " << l << ", vertices " << a << " and " << b;
      }
  }
  EXPECT_EQ(grounded, 2u);
}

TEST(Behaviour, NoDetachmentByDefault) {
  const TreeModel model = testing::small_tree(6);
  Simulator sim(model, HsmOptions{}, gust_then_calm(40, 2, 2.5), 1.0 / 24, 4);
  SimState state = sim.initial_state(0);
  for (int f = 1; f <= 48; ++f) sim.advance_frame(state, f);
  for (uint8_t a : state.leaf_attached) EXPECT_EQ(a, 1);
}

TEST(Behaviour, LeafDragBendsItsBranch) {
  // A leaf's drag loads its branch through the bar chain, as it loads a real one: the branch
  // vertices bend farther with drag on the leaves than without, and the leaves feel it too.
  const TreeModel model = testing::small_tree(6);
  WindOptions wind = gust_then_calm(12, 2, 2.5);
  std::vector<Eigen::Matrix3Xd> bakes;
  for (double leaf_drag : {0.6, 0.0}) {
    wind.leaf_drag_coefficient = leaf_drag;
    Simulator sim(model, HsmOptions{}, wind, 1.0 / 24, 4);
    SimState state = sim.initial_state(0);
    for (int f = 1; f <= 36; ++f) sim.advance_frame(state, f);
    bakes.push_back(state.positions);
  }
  double with_leaves = 0, without = 0, leaf_difference = 0;
  for (size_t v = 0; v < model.vertex_count(); ++v) {
    if (model.vertex_leaf[v] < 0) {
      with_leaves = std::max(with_leaves, (bakes[0].col(v) - model.rest_positions.col(v)).norm());
      without = std::max(without, (bakes[1].col(v) - model.rest_positions.col(v)).norm());
    } else {
      leaf_difference = std::max(leaf_difference, (bakes[0].col(v) - bakes[1].col(v)).norm());
    }
  }
  EXPECT_GT(with_leaves, 1.2 * without);
  EXPECT_GT(leaf_difference, 1e-3);
}

TEST(Behaviour, SleepingBakeMatchesTheFullBake) {
  const TreeModel model = grown_tree(5, 2, 4);
  const WindOptions wind = gust_then_calm(10, 2, 2.5);
  HsmOptions awake;
  awake.sleep = false;
  Simulator full(model, awake, wind, 1.0 / 24, 4);
  Simulator sleeping(model, HsmOptions{}, wind, 1.0 / 24, 4);
  SimState a = full.initial_state(0), b = sleeping.initial_state(0);
  double worst = 0;
  for (int f = 1; f <= 24 * 20; ++f) {
    full.advance_frame(a, f);
    sleeping.advance_frame(b, f);
    worst = std::max(worst, (a.positions - b.positions).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(worst, 1e-5);
  for (uint8_t asleep : b.island_asleep) EXPECT_EQ(asleep, 1);
  EXPECT_EQ(b.positions, model.rest_positions);  // put to sleep exactly at rest
  // ... and woken by the next wind.
  WindOptions again = wind;
  again.keys.push_back({25, 10, {1, 0, 0}, 0});
  Simulator woken(model, HsmOptions{}, again, 1.0 / 24, 4);
  b.time = 25;
  woken.advance_frame(b, 24 * 25 + 1);
  EXPECT_EQ(b.island_asleep[0], 0);
  EXPECT_GT(max_displacement(b, model), 0);
}

TEST(Behaviour, TheTreeDownwindSwaysLikeTheOneUpwindLater) {
  // Two identical trees 24 m apart along an 8 m/s wind: the gusts and the frozen turbulence
  // (no evolution in place) reach the second 3 s = 72 frames later, and so does its sway once
  // both have forgotten their start. A third, 1 m across the wind from the first, sways alike
  // in eddies of a forest's size (turbulence_length 16 m; docs/solver.md "Wind and forces").
  WindOptions wind;
  wind.keys = {{0, 8, {1, 0, 0}, 3}};
  wind.turbulence_length = 16;
  wind.turbulence_frequency = 0;
  const Eigen::Vector3d upwind(-10, 0, 5);
  const int frames = 24 * 40;
  const size_t settled = 24 * 10;
  const std::vector<Eigen::Vector3d> a = testing::tip_motion(upwind, wind, frames),
                                     b = testing::tip_motion(upwind + Eigen::Vector3d(24, 0, 0), wind, frames),
                                     c = testing::tip_motion(upwind + Eigen::Vector3d(0, 0, 1), wind, frames);
  const size_t lag = best_lag(a, b, settled, 24 * 6);
  EXPECT_NEAR(double(lag), 72, 1);
  EXPECT_GT(correlation(a, b, settled, lag), 0.99);
  EXPECT_LT(correlation(a, b, settled, 0), 0.9);
  EXPECT_GT(correlation(a, c, settled, 0), 0.95);
  RecordProperty("lag_frames", int(lag));
  RecordProperty("correlation_at_lag", std::to_string(correlation(a, b, settled, lag)));
  RecordProperty("correlation_1m_across", std::to_string(correlation(a, c, settled, 0)));
}

TEST(Behaviour, IdenticalBytesFor1And2And4Threads) {
  const TreeModel model = grown_tree(7, 2, 2);
  ASSERT_GE(model.membership_count(), kParallelMemberships);  // large enough to run in parallel
  WindOptions wind = gust_then_calm(18, 1, 1.5);
  for (Precision precision : {Precision::kDouble, Precision::kFloat}) {
    SCOPED_TRACE(precision == Precision::kFloat ? "float" : "double");
    HsmOptions options;
    options.leaf_detach_force = 0.01;
    options.precision = precision;
    std::vector<SimState> results;
    const int saved = omp_get_max_threads();
    for (int threads : {1, 2, 4}) {
      omp_set_num_threads(threads);
      Simulator sim(model, options, wind, 1.0 / 24, 3);
      SimState state = sim.initial_state(0);
      for (int f = 1; f <= 36; ++f) sim.advance_frame(state, f);
      results.push_back(state);
    }
    omp_set_num_threads(saved);
    for (size_t k = 1; k < results.size(); ++k) {
      EXPECT_EQ(std::memcmp(results[0].positions.data(), results[k].positions.data(),
                            sizeof(double) * results[0].positions.size()), 0);
      EXPECT_EQ(std::memcmp(results[0].velocities.data(), results[k].velocities.data(),
                            sizeof(double) * results[0].velocities.size()), 0);
      EXPECT_EQ(results[0].leaf_attached, results[k].leaf_attached);
    }
    size_t detached = 0;
    for (uint8_t a : results[0].leaf_attached) detached += a == 0;
    EXPECT_GT(detached, 0u);  // the detachment path ran too
  }
}

TEST(Behaviour, FloatBakeFollowsTheDoubleBake) {
  // The float solver rounds its step state to ~1e-7 relative; over 2 s of gusts, with leaves,
  // its motion must stay a small fraction of the double bake's (the step's own error at the
  // default substeps is ~1 %: docs/benchmarks.md).
  const TreeModel model = grown_tree(6, 2, 2);
  const WindOptions wind = gust_then_calm(12, 1.5, 2);
  HsmOptions double_options, float_options;
  float_options.precision = Precision::kFloat;
  Simulator double_sim(model, double_options, wind, 1.0 / 24, 16), float_sim(model, float_options, wind, 1.0 / 24, 16);
  SimState double_state = double_sim.initial_state(0), float_state = float_sim.initial_state(0);
  double sway = 0, difference = 0;  // m, the largest over the frames
  for (int f = 1; f <= 48; ++f) {
    double_sim.advance_frame(double_state, f);
    float_sim.advance_frame(float_state, f);
    sway = std::max(sway, max_displacement(double_state, model));
    difference = std::max(difference, (float_state.positions - double_state.positions).colwise().norm().maxCoeff());
  }
  EXPECT_GT(sway, 0.01);
  EXPECT_GT(difference, 0.0);  // the float path did run
  EXPECT_LT(difference, 1e-3 * sway) << "sway " << sway << " m";
}

// Final positions after 1.5 s of a rising wind, at 4, 8, 16 and 32 substeps per frame =>
// (largest difference to the 32-substep result, largest displacement of that result).
std::pair<double, double> substep_spread(const TreeModel& model, const HsmOptions& options) {
  WindOptions wind;
  wind.keys = {{0, 0, {1, 0, 0}, 0}, {0.5, 20, {1, 0, 0}, 0}};
  wind.turbulence_intensity = 0;
  std::vector<Eigen::Matrix3Xd> finals;
  for (int substeps : {4, 8, 16, 32}) {
    Simulator sim(model, options, wind, 1.0 / 24, substeps);
    SimState state = sim.initial_state(0);
    for (int f = 1; f <= 36; ++f) sim.advance_frame(state, f);
    finals.push_back(state.positions);
  }
  double spread = 0;
  for (size_t k = 0; k + 1 < finals.size(); ++k)
    spread = std::max(spread, (finals[k] - finals.back()).colwise().norm().maxCoeff());
  return {spread, (finals.back() - model.rest_positions).colwise().norm().maxCoeff()};
}

TEST(Behaviour, SubstepCountDoesNotChangeThePhysicalMotion) {
  // Physical stiffness: the same motion at 4 to 32 substeps (within 1% of the sway).
  const TreeModel model = grown_tree(5, 0, 4);
  const auto [physical_spread, physical_sway] = substep_spread(model, HsmOptions{});
  EXPECT_GT(physical_sway, 0.005);
  EXPECT_LT(physical_spread, 0.01 * physical_sway);
}

// Damping ratio 10 (the range's top) on a 2 m stem: overdamped, it creeps toward its bend
// in a steady 15 m/s wind (rate about 1/s), as far after 0.5 s at the default 2 substeps as
// at 128. A kick between two exactly damped half steps crept 1/40 as fast as it should at 2
// substeps (0.79 against 5.14 mm).
TEST(Behaviour, AnOverdampedStemCreepsAsFastAtAnyStep) {
  LsystemOptions lsystem;
  lsystem.axiom = "!(0.04)F(0.25)F(0.25)F(0.25)F(0.25)F(0.25)F(0.25)F(0.25)F(0.25)";
  lsystem.iterations = 0;
  TreeOptions tree;
  tree.tip_taper = 1;
  const TreeModel model = build_tree_model(grow_skeleton(lsystem, nullptr), tree);
  HsmOptions options;
  options.damping_ratio = 10;
  options.root_flexibility = 0;
  WindOptions wind;
  wind.turbulence_intensity = 0;
  wind.keys = {{0, 15, {1, 0, 0}, 0}};
  auto tip_after = [&](int substeps) {
    Simulator sim(model, options, wind, 1.0 / 24, substeps);
    SimState state = sim.initial_state(0);
    for (int f = 1; f <= 12; ++f) sim.advance_frame(state, f);
    return (state.positions.row(0) - model.rest_positions.row(0)).maxCoeff();
  };
  const double converged = tip_after(128);
  EXPECT_GT(converged, 0.003);  // m: well on its way to its 13 mm bend
  EXPECT_NEAR(tip_after(2), converged, 0.03 * converged);
  EXPECT_NEAR(tip_after(1), converged, 0.15 * converged);
  // Coarser single steps (x = zeta w h past 10), in float and double: the stem still creeps. With
  // the kick's scale capped at x = 10 and the damping not, it crept 0.4 mm of 5.3 in 0.5 s at 16
  // steps a second and 7e-10 m at 8; now 3.5 and 0.9 mm. What is left is the step's capped
  // stiffness (a frequency it does not resolve pulls at most its whole way a step).
  auto tip_after_seconds = [&](int fps, int substeps) {
    Simulator sim(model, options, wind, 1.0 / fps, substeps);
    SimState state = sim.initial_state(0);
    for (int f = 1; f <= fps / 2; ++f) sim.advance_frame(state, f);
    EXPECT_TRUE(state.positions.allFinite());
    return (state.positions.row(0) - model.rest_positions.row(0)).maxCoeff();
  };
  for (const Precision precision : {Precision::kFloat, Precision::kDouble}) {
    options.precision = precision;
    const double slow = tip_after_seconds(16, 64);
    EXPECT_GT(slow, 0.004);
    EXPECT_GT(tip_after_seconds(16, 1), 0.5 * slow);
    EXPECT_GT(tip_after_seconds(8, 1), 0.1 * slow);
  }
}

TEST(Behaviour, ConvergesAtSecondOrderInTheStep) {
  // With physical stiffness the error against a converged small-step bake (512 substeps)
  // falls as h^2, order 1.7-2.3 (scripts/bench-accuracy measures the same on larger trees),
  // here on a young tree with leaves in a turbulent 5 m/s wind that starts at once.
  const TreeModel model = grown_tree(4, 2, 4);
  WindOptions wind;  // 5 m/s from frame 0, with the default turbulence
  wind.keys = {{0, 5, {1, 0, 0.2}, 0}};
  std::vector<Eigen::Matrix3Xd> bakes;  // frames side by side, per substep count
  const std::vector<int> substeps = {2, 4, 8, 512};
  for (int n : substeps) {
    Simulator sim(model, HsmOptions{}, wind, 1.0 / 24, n);
    SimState state = sim.initial_state(0);
    Eigen::Matrix3Xd frames(3, model.vertex_count() * 24);
    for (int f = 1; f <= 24; ++f) {
      sim.advance_frame(state, f);
      frames.middleCols(model.vertex_count() * (f - 1), model.vertex_count()) = state.positions - model.rest_positions;
    }
    bakes.push_back(frames);
  }
  // docs/benchmarks.md's measure: mass-weighted RMS error over all frames and vertices, over
  // the reference's mass-weighted RMS displacement.
  Eigen::RowVectorXd weight(bakes.back().cols());
  for (Eigen::Index c = 0; c < weight.size(); ++c) weight[c] = std::sqrt(model.vertex_mass[c % model.vertex_count()]);
  const Eigen::Matrix3Xd reference = bakes.back().array().rowwise() * weight.array();
  std::vector<double> error;
  for (size_t k = 0; k + 1 < bakes.size(); ++k) {
    const Eigen::Matrix3Xd bake = bakes[k].array().rowwise() * weight.array();
    error.push_back((bake - reference).norm() / reference.norm());
    std::printf("%d substeps: error %.3e of the motion\n", substeps[k], error.back());
  }
  for (size_t k = 0; k + 1 < error.size(); ++k) {
    const double order = std::log2(error[k] / error[k + 1]);
    EXPECT_GT(order, 1.7) << substeps[k] << " -> " << substeps[k + 1] << " substeps";
    EXPECT_LT(order, 2.3) << substeps[k] << " -> " << substeps[k + 1] << " substeps";
  }
  EXPECT_LT(error[1], 0.01);  // 4 substeps, the default
}

}  // namespace
}  // namespace treeanim
