// The bar chain against Euler-Bernoulli (docs/solver.md, "Bending"): the cantilever of
// configs/cantilever.json grown through the L-system and the tree builder, in a steady wind
// (its static deflection along the span) and plucked (its first frequency). The builder
// tapers the last segment to half the radius (a tip), which the uniform beam does not have:
// it takes a few per cent of the load off the tip.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "grown_tree.h"
#include "lsystem/lsystem.h"
#include "sim/bar_chain.h"
#include "sim/simulator.h"
#include "sim/solver_model.h"
#include "sim/solver_step.h"
#include "sim/particle_model.h"
#include "sim/sample_skin.h"
#include "tree/build_tree_model.h"

namespace treeanim {
namespace {

constexpr double kLength = 2, kRadius = 0.02, kModulus = 8e9, kDensity = 700;

// A straight branch of kLength in `segments` segments, radius kRadius, its base anchored.
TreeModel cantilever(int segments) {
  LsystemOptions lsystem;
  lsystem.axiom = "!(" + std::to_string(2 * kRadius) + ")";
  for (int s = 0; s < segments; ++s) lsystem.axiom += "F(" + std::to_string(kLength / segments) + ")";
  lsystem.iterations = 0;
  TreeOptions tree;
  tree.ring_sides = 8;
  tree.wood_density = kDensity;
  GrowthStats stats;
  return build_tree_model(grow_skeleton(lsystem, &stats), tree);
}

HsmOptions cantilever_options(double damping_ratio) {
  HsmOptions options;
  options.youngs_modulus = kModulus;
  options.damping_ratio = damping_ratio;
  options.max_frequency = 120;
  options.max_limb_frequency = 120;
  options.root_flexibility = 0;  // clamped, as Euler-Bernoulli's cantilever
  options.sleep = false;
  return options;
}

// Bake => mean displacement along x of the ring vertices at height s (m).
double deflection_at(const TreeModel& model, const SimState& state, double s) {
  double sum = 0;
  int count = 0;
  for (size_t v = 0; v < model.vertex_count(); ++v)
    if (std::abs(model.rest_positions(1, v) - s) < 1e-6) {
      sum += state.positions(0, v) - model.rest_positions(0, v);
      ++count;
    }
  return count ? sum / count : std::nan("");
}

// The cut for the chain's walks (BarChain::walk_trunk, walk_groups): every cluster once, each
// list ascending, the trunk closed toward the roots, and all children of a cluster in one
// place (the trunk or one group), so that no two threads add into one parent.
void expect_walk_cut(const TreeModel& tree) {
  const BarChain chain = build_bar_chain(tree, HsmOptions{});
  const size_t C = tree.cluster_count();
  std::vector<int> place(C, -2);  // -1: trunk, g: group g
  ASSERT_TRUE(std::is_sorted(chain.walk_trunk.begin(), chain.walk_trunk.end()));
  for (uint32_t c : chain.walk_trunk) {
    ASSERT_LT(c, C);
    EXPECT_EQ(place[c], -2) << "cluster " << c << " twice";
    place[c] = -1;
  }
  ASSERT_GE(chain.walk_group_offsets.size(), 2u);
  EXPECT_EQ(chain.walk_group_offsets.back(), chain.walk_groups.size());
  size_t largest = 0;
  for (size_t g = 0; g + 1 < chain.walk_group_offsets.size(); ++g) {
    const auto first = chain.walk_groups.begin() + chain.walk_group_offsets[g];
    const auto last = chain.walk_groups.begin() + chain.walk_group_offsets[g + 1];
    EXPECT_TRUE(std::is_sorted(first, last));
    largest = std::max<size_t>(largest, last - first);
    for (auto it = first; it != last; ++it) {
      ASSERT_LT(*it, C);
      EXPECT_EQ(place[*it], -2) << "cluster " << *it << " twice";
      place[*it] = int(g);
    }
  }
  std::vector<int> children_place(C, -2);
  for (size_t c = 0; c < C; ++c) {
    ASSERT_NE(place[c], -2) << "cluster " << c << " in no walk";
    const int32_t p = tree.cluster_parent[c];
    if (p < 0) {
      EXPECT_EQ(place[c], -1) << "root cluster " << c << " outside the trunk";
      continue;
    }
    if (place[c] == -1) {
      EXPECT_EQ(place[p], -1) << "trunk cluster " << c << " below a limb";
    }
    if (children_place[p] == -2) children_place[p] = place[c];
    EXPECT_EQ(children_place[p], place[c]) << "children of cluster " << p << " in two walks";
    if (place[c] >= 0) {
      EXPECT_TRUE(place[p] == place[c] || place[p] == -1) << "cluster " << c;
    }
  }
  // The limbs are dealt evenly: no group holds much more than its share.
  EXPECT_LE(largest, C / 16 + C / 64 + 1);
}

TEST(Beam, WalkCutSplitsTheClusterTreeIntoDisjointLimbs) {
  expect_walk_cut(testing::grown_tree(5, 2, 2));
  expect_walk_cut(cantilever(12));
  expect_walk_cut(cantilever(1));
}

TEST(Beam, GoalRunsHoldVerticesInTheSameClustersWithConsecutiveMemberships) {
  // The goal writes take a run as one loop on its clusters' poses and the next arm of each
  // (beam_statics.cpp): every vertex of a run must be in the same clusters, in the same order,
  // at the next membership of each, and none a leaf's shared vertex (whose memberships may be
  // released). Overlap rings make runs of vertices in two clusters.
  const TreeModel tree = testing::grown_tree(5, 2, 2);
  const SolverModel<float> model(tree, HsmOptions{}, WindOptions{}, 1.0 / 24, 2);
  std::vector<uint8_t> leaf_shared(tree.vertex_count(), 0);
  for (uint32_t v : tree.leaf_attachment_vertex) leaf_shared[v] = 1;
  const auto& offsets = tree.vertex_cluster_offsets;
  size_t in_runs = 0, shared_in_runs = 0, previous_end = 0;
  for (const VertexRun& run : model.vertex_runs) {
    const size_t v = run.begin, end = run.end;
    ASSERT_GE(v, previous_end);  // ascending, disjoint
    ASSERT_GT(end, v);
    ASSERT_LE(end, tree.vertex_count());
    const uint32_t n = offsets[v + 1] - offsets[v];
    ASSERT_EQ(run.count, n);
    ASSERT_GE(n, 1u);
    ASSERT_LE(n, kMaxRunClusters);
    for (size_t u = v; u < end; ++u) {
      ASSERT_FALSE(leaf_shared[u]) << u;
      ASSERT_EQ(offsets[u + 1] - offsets[u], n) << u;
      for (uint32_t j = 0; j < n; ++j) {
        const uint32_t first = run.first_slot[j], slot = tree.vertex_memberships[offsets[u] + j];
        ASSERT_EQ(first, tree.vertex_memberships[offsets[v] + j]);
        ASSERT_EQ(run.cluster[j], model.tree.member_cluster[first]);
        ASSERT_EQ(slot, first + (u - v)) << u;
        ASSERT_EQ(model.tree.member_cluster[slot], model.tree.member_cluster[first]) << u;
        ASSERT_EQ(tree.cluster_members[slot], u);
      }
    }
    // A run is as long as it can be: the next vertex does not continue it.
    if (end < tree.vertex_count() && offsets[end + 1] - offsets[end] == n && !leaf_shared[end]) {
      bool continues = true;
      for (uint32_t j = 0; j < n; ++j)
        continues = continues && tree.vertex_memberships[offsets[end] + j] == run.first_slot[j] + (end - v) &&
                    model.tree.member_cluster[tree.vertex_memberships[offsets[end] + j]] == model.tree.member_cluster[run.first_slot[j]];
      EXPECT_FALSE(continues) << end;
    }
    in_runs += end - v;
    if (n > 1) shared_in_runs += end - v;
    previous_end = end;
  }
  EXPECT_GT(in_runs + 4 * model.leaf_cards.size(), tree.vertex_count() * 9 / 10);
  EXPECT_GT(shared_in_runs, 0u);
}

TEST(Beam, GoalsAreTheSameBitsWhetherACardRunOrAVertexWritesThem) {
  // A leaf's card takes its four vertices in one vector's lanes (beam_statics.cpp); a range that
  // cuts it takes them one by one, through each vertex's memberships. Both must give the same
  // bits, for cards with a released membership too, in both precisions of the build.
  const TreeModel tree = testing::grown_tree(4, 2, 2);
  auto expect_same = [&](auto real) {
    using Real = decltype(real);
    const SolverModel<Real> model(tree, HsmOptions{}, WindOptions{}, 1.0 / 24, 2);
    ASSERT_GE(model.leaf_cards.size(), 2u);
    Attachment<Real> attachment = model.all_attached;
    for (const uint32_t slot : {model.leaf_cards[0].pin_slot, model.leaf_cards[1].slot + 2})
      attachment.member_active[slot] = 0;
    attachment.vertex_inv_count[model.leaf_cards[0].vertex] = 1;
    attachment.vertex_inv_count[model.leaf_cards[1].vertex + 2] = 0;
    StepScratch<Real> scratch(model);
    std::mt19937 random(7);
    std::uniform_real_distribution<double> any(-0.3, 0.3);
    for (Eigen::Index i = 0; i < scratch.cluster_pose.size(); ++i) scratch.cluster_pose.data()[i] = Real(any(random));
    StepPrediction<Real> whole, single;
    for (StepPrediction<Real>* p : {&whole, &single}) {
      p->goal.setConstant(model.V, 3, Real(9));
      p->damping_compliance.setConstant(model.V, Real(9));
    }
    write_static_offsets(model, attachment, scratch, whole, 0, model.V);
    for (size_t v = 0; v < model.V; ++v) write_static_offsets(model, attachment, scratch, single, v, v + 1);
    EXPECT_EQ(std::memcmp(whole.goal.data(), single.goal.data(), sizeof(Real) * whole.goal.size()), 0);
    EXPECT_EQ(std::memcmp(whole.damping_compliance.data(), single.damping_compliance.data(),
                          sizeof(Real) * model.V),
              0);
    EXPECT_EQ(whole.goal(model.leaf_cards[1].vertex + 2, 0), Real(0));  // a released vertex's goal
  };
  expect_same(float{});
  expect_same(double{});
}

TEST(Beam, CorrectionRowsAreOneAMembershipAndAFreeVertexInOneClusterWritesItsOwn) {
  // The fit writes each membership's correction to its own row (the vertex passes read a free
  // vertex in one cluster from its vertex row, in order); the rows of a cluster's runs follow
  // its memberships one by one, and an anchor's vertex row is never written.
  const TreeModel tree = testing::grown_tree(5, 2, 2);
  const SolverModel<float> model(tree, HsmOptions{}, WindOptions{}, 1.0 / 24, 2);
  const auto& offsets = tree.vertex_cluster_offsets;
  std::vector<uint8_t> used(model.V + model.M, 0);
  for (size_t v = 0; v < model.V; ++v)
    for (uint32_t k = offsets[v]; k < offsets[v + 1]; ++k) {
      const uint32_t slot = tree.vertex_memberships[k], row = model.member_correction_row[slot];
      const bool own = !tree.vertex_anchored[v] && offsets[v + 1] - offsets[v] == 1;
      if (own) {
        EXPECT_EQ(row, v);
      } else {
        EXPECT_GE(row, model.V) << v;
      }
      ASSERT_LT(row, used.size());
      EXPECT_FALSE(used[row]) << row;
      used[row] = 1;
    }
  for (size_t c = 0; c < model.C; ++c) {
    uint32_t next = tree.cluster_offsets[c];
    for (uint32_t i = model.correction_run_offsets[c]; i < model.correction_run_offsets[c + 1]; ++i) {
      const CorrectionRun& run = model.correction_runs[i];
      ASSERT_EQ(run.begin, next);
      ASSERT_GT(run.end, run.begin);
      for (uint32_t s = run.begin; s < run.end; ++s) {
        EXPECT_EQ(model.member_correction_row[s], run.row + (s - run.begin)) << s;
        if (run.row < model.V) {
          EXPECT_EQ(tree.cluster_members[s], run.row + (s - run.begin)) << s;
        }
      }
      next = run.end;
    }
    EXPECT_EQ(next, tree.cluster_offsets[c + 1]) << c;
  }
  size_t shared = 0;
  for (size_t v = 0; v < model.V; ++v) shared += !tree.vertex_anchored[v] && offsets[v + 1] - offsets[v] > 1;
  EXPECT_EQ(model.shared_vertices.size(), shared);
  EXPECT_GT(shared, 0u);
}

TEST(Beam, AClusterIsMarkedReleasedExactlyWhenItLostAMembership) {
  // The loops over a cluster's members read the members' flags only where
  // Attachment::cluster_released says one was released; detaching leaves must keep it exact.
  const TreeModel tree = testing::grown_tree(5, 2, 2);
  const SolverModel<float> model(tree, HsmOptions{}, WindOptions{}, 1.0 / 24, 2);
  ASSERT_GT(model.L, 2u);
  SimState state;
  state.leaf_attached.assign(model.L, 1);
  for (size_t l = 0; l < model.L; l += 2) state.leaf_attached[l] = 0;
  Attachment<float> attachment = model.all_attached;
  adopt_leaf_flags(model, state, attachment);
  size_t released = 0;
  for (size_t c = 0; c < model.C; ++c) {
    bool lost = false;
    for (uint32_t s = tree.cluster_offsets[c]; s < tree.cluster_offsets[c + 1]; ++s) lost = lost || !attachment.member_active[s];
    EXPECT_EQ(attachment.cluster_released[c] != 0, lost) << c;
    released += lost;
  }
  EXPECT_GT(released, 0u);
  EXPECT_TRUE(std::none_of(model.all_attached.cluster_released.begin(), model.all_attached.cluster_released.end(),
                           [](uint8_t r) { return r != 0; }));
}

// The cantilever's mesh after `frames` frames: simulated on its vertices, or on its samples and
// placed from them (hsm.particles "samples"), the mesh at every frame handed to `visit`.
template <typename Visit>
void bake_cantilever(const TreeModel& model, bool samples, const HsmOptions& options, const WindOptions& wind,
                     int frames, Visit&& visit) {
  const TreeModel sampled = samples ? sample_tree_model(model) : TreeModel{};
  const SampleSkin skin(model, samples ? sampled : model);
  Simulator sim(samples ? sampled : model, options, wind, 1.0 / 240, 4);
  SimState state = sim.initial_state(0), mesh;
  ClusterFrames frames_scratch;
  for (int f = 1; f <= frames; ++f) {
    sim.advance_frame(state, f);
    if (samples) skin.pose(state, false, frames_scratch, mesh);
    visit(samples ? mesh : state);
  }
}

void cantilever_bends_like_euler_bernoulli(bool samples) {
  // Uniform drag load q = 1/2 rho Cd (2r) U^2 on a clamped-free beam:
  // delta(x) = q L^4 (x^4 - 4x^3 + 6x^2) / (24 E I), x = s / L. Settled with critical damping.
  const double U = 15;
  WindOptions wind;
  wind.turbulence_intensity = 0;
  wind.keys = {{0, 0, {1, 0, 0}, 0}, {0.2, U, {1, 0, 0}, 0}};
  const double q = 0.5 * wind.air_density * wind.branch_drag_coefficient * 2 * kRadius * U * U;
  const double EI = kModulus * std::numbers::pi * std::pow(kRadius, 4) / 4;
  for (int segments : {8, 16}) {
    const TreeModel model = cantilever(segments);
    SimState state;
    bake_cantilever(model, samples, cantilever_options(1.0), wind, 480, [&](const SimState& s) { state = s; });
    for (double x : {0.25, 0.5, 0.75, 1.0}) {
      const double expected = q * std::pow(kLength, 4) * (x * x * x * x - 4 * x * x * x + 6 * x * x) / (24 * EI);
      const double measured = deflection_at(model, state, x * kLength);
      std::printf("%s, %d segments, x = %.2f L: %.3f mm, Euler-Bernoulli %.3f mm\n", samples ? "samples" : "vertices",
                  segments, x, 1e3 * measured, 1e3 * expected);
      EXPECT_NEAR(measured, expected, 0.10 * expected) << segments << " segments, x = " << x;
    }
  }
}

TEST(Beam, CantileverInASteadyWindBendsLikeEulerBernoulli) { cantilever_bends_like_euler_bernoulli(false); }
TEST(Beam, SampledCantileverInASteadyWindBendsLikeEulerBernoulli) { cantilever_bends_like_euler_bernoulli(true); }

void plucked_cantilever_sways_at_its_first_frequency(bool samples) {
  // f1 = 1.8751^2 / (2 pi L^2) sqrt(E I / (rho A)), within 10 %: a 0.3 s gust, then free
  // vibration, timed by the zero crossings of the tip's deflection over 2 s.
  WindOptions wind;
  wind.turbulence_intensity = 0;
  wind.keys = {{0, 0, {1, 0, 0}, 0}, {0.02, 15, {1, 0, 0}, 0}, {0.3, 15, {1, 0, 0}, 0}, {0.32, 0, {1, 0, 0}, 0}};
  const double f1 = std::pow(1.8751040687, 2) / (2 * std::numbers::pi * kLength * kLength) *
                    std::sqrt(kModulus * kRadius * kRadius / 4 / kDensity);
  for (int segments : {8, 16}) {
    const TreeModel model = cantilever(segments);
    double last = 0, first_crossing = -1, last_crossing = -1;
    int crossings = 0;
    bake_cantilever(model, samples, cantilever_options(0.02), wind, 240 * 3, [&](const SimState& state) {
      if (state.time < 0.5) return;
      const double tip = deflection_at(model, state, kLength);
      if (last != 0 && (tip > 0) != (last > 0)) {
        if (first_crossing < 0) first_crossing = state.time;
        last_crossing = state.time;
        ++crossings;
      }
      last = tip;
    });
    ASSERT_GE(crossings, 10);
    const double measured = (crossings - 1) / (2 * (last_crossing - first_crossing));
    std::printf("%s, %d segments: %.3f Hz, Euler-Bernoulli %.3f Hz\n", samples ? "samples" : "vertices", segments,
                measured, f1);
    EXPECT_NEAR(measured, f1, 0.10 * f1) << segments << " segments";
  }
}

TEST(Beam, PluckedCantileverSwaysAtItsFirstFrequency) { plucked_cantilever_sways_at_its_first_frequency(false); }
TEST(Beam, SampledPluckedCantileverSwaysAtItsFirstFrequency) { plucked_cantilever_sways_at_its_first_frequency(true); }


TEST(Beam, TheSamplesMeanTurnIsTheCappedMeanWhereNoPointYields) {
  // "samples" takes a joint's unscented mean turn in one cross product wherever no point of the
  // transform can reach its yield turn, and the turns' matrices by their series
  // (SolverModel::quick_chain); "vertices" takes the six capped turns and the library's
  // rotation. The deflected chain is the same but for round-off, in gusts that leave air
  // unresolved and under loads a thousand times larger, where joints yield.
  const TreeModel tree = testing::grown_tree(5, 2, 2);
  const WindOptions wind = testing::gust_then_calm(20, 5, 6);
  HsmOptions sampled;
  sampled.particles = ParticleMode::kSamples;
  const SolverModel<double> quick(tree, sampled, wind, 1.0 / 24, 2), exact(tree, HsmOptions{}, wind, 1.0 / 24, 2);
  ASSERT_TRUE(quick.quick_chain && !exact.quick_chain);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> unit(-1, 1);
  for (double scale : {0.01, 10.0}) {
    SimState state;
    Rows3<double>& drag = state.prediction<double>().drag_force;
    drag.resize(long(tree.vertex_count()), 3);
    for (long v = 0; v < drag.rows(); ++v) drag.row(v) = scale * Eigen::RowVector3d(1 + unit(rng), unit(rng), unit(rng));
    StepScratch<double> a(quick), b(exact);
    for (size_t v = 0; v < tree.vertex_count(); ++v)
      a.vertex_drag_damping[v] = b.vertex_drag_damping[v] = scale * (1 + unit(rng));
    set_air_time(quick, 1.0, a);
    set_air_time(exact, 1.0, b);
    ASSERT_GT(a.air.unresolved.trace(), 0);
    deflect_bar_chain(quick, quick.all_attached, state, a);
    deflect_bar_chain(exact, exact.all_attached, state, b);
    size_t yielded = 0;
    for (size_t c = 0; c < quick.C; ++c) {
      const Eigen::AngleAxisd turn(Eigen::Matrix3d(Eigen::Map<const Eigen::Matrix3d>(&b.cluster_static_rotation(0, c))));
      yielded += quick.chain.cluster_max_turn[c] < 10 && turn.angle() > 0.5 * quick.chain.cluster_max_turn[c];
    }
    EXPECT_LT((a.cluster_static_rotation - b.cluster_static_rotation).cwiseAbs().maxCoeff(), 1e-12) << scale;
    EXPECT_LT((a.cluster_static_joint - b.cluster_static_joint).cwiseAbs().maxCoeff(), 1e-12) << scale;
    if (scale > 1) {
      EXPECT_GT(yielded, 0u);
    }
    std::printf("loads x %g: %zu joints turned past half their yield\n", scale, yielded);
  }
}

}  // namespace
}  // namespace treeanim
