// The solver step on hand-built models: exact goals, alpha = 1, rest stability, averaging,
// anchors, NaN reporting.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <random>

#include "common/errors.h"
#include "sim/simulator.h"
#include "sim/stiffness.h"
#include "sim/wind.h"
#include "sim_test_models.h"

namespace treeanim {
namespace {

using testing::ModelBuilder;
using testing::small_tree;

HsmOptions per_step(double alpha, double k_d, bool global) {
  HsmOptions o;
  o.stiffness = StiffnessMode::kPerStep;
  o.alpha = alpha;
  o.leaf_alpha = alpha;
  o.k_d = k_d;
  o.global_matching = global;
  o.sleep = false;
  return o;
}

WindOptions calm() { return WindOptions{}; }

// Steady wind of `speed` (m/s) along `direction` with gusts of `gust` (m/s).
WindOptions steady_wind(double speed, const Eigen::Vector3d& direction, double gust) {
  WindOptions wind;
  wind.keys = {{0, speed, direction, gust}};
  return wind;
}

// Physical defaults with sleeping off, so that every step really runs.
HsmOptions awake() {
  HsmOptions options;
  options.sleep = false;
  return options;
}

// Frames [first, last] of a bake.
void advance(Simulator& sim, SimState& state, int first, int last) {
  for (int f = first; f <= last; ++f) sim.advance_frame(state, f);
}

// One free (unanchored) branch cluster of two rings, far from the origin.
TreeModel single_cluster(const Eigen::Vector3d& origin) {
  ModelBuilder b;
  b.add_branch(origin, {0.2, 1, 0.1}, 0.5, 1, 0.05, 0.03, -1, false, 5);
  return b.finish();
}

TEST(Solver, RigidlyMovedRestPoseIsItsOwnGoal) {
  // Far from the origin, no anchors, no forces, global term off: every cluster's goal is the
  // moved rest pose, so nothing moves and the extracted rotation is the applied one.
  TreeModel model = small_tree(2, Eigen::Vector3d(5000, 20, -3000));
  std::fill(model.vertex_anchored.begin(), model.vertex_anchored.end(), 0);
  HsmOptions options = per_step(0.7, 0, false);
  options.rotation_iterations = 100;  // a cold start 0.8 rad away; the bake warm-starts
  Simulator sim(model, options, calm(), 1.0 / 24, 1);
  SimState state = sim.initial_state(0);
  const Eigen::Quaterniond rotation(Eigen::AngleAxisd(0.8, Eigen::Vector3d(1, 2, -0.5).normalized()));
  const Eigen::Vector3d shift(3.25, -1.5, 0.75);
  for (Eigen::Index v = 0; v < state.positions.cols(); ++v)
    state.positions.col(v) = rotation * model.rest_positions.col(v) + shift;
  // Warm starts at identity: the extraction must find the full rotation within its iterations.
  const Eigen::Matrix3Xd moved = state.positions;
  sim.advance_frame(state, 1);
  EXPECT_LT((state.positions - moved).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT(state.velocities.cwiseAbs().maxCoeff(), 1e-7);
  for (Eigen::Index c = 0; c < state.cluster_rotations.cols(); ++c)
    EXPECT_LT(Eigen::Quaterniond(state.cluster_rotations.col(c)).angularDistance(rotation), 1e-9) << c;
}

// Independent reference: goals of one cluster (rest points x0, masses m, current points x)
// by SVD polar decomposition of A_pq.
Eigen::Matrix3Xd reference_goals(const Eigen::Matrix3Xd& x0, const std::vector<double>& m, const Eigen::Matrix3Xd& x) {
  const Eigen::Index n = x.cols();
  double total = 0;
  Eigen::Vector3d c0 = Eigen::Vector3d::Zero(), c = Eigen::Vector3d::Zero();
  for (Eigen::Index i = 0; i < n; ++i) {
    total += m[i];
    c0 += m[i] * x0.col(i);
    c += m[i] * x.col(i);
  }
  c0 /= total;
  c /= total;
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  for (Eigen::Index i = 0; i < n; ++i) A += m[i] * (x.col(i) - c) * (x0.col(i) - c0).transpose();
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(A, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d R = svd.matrixU() * svd.matrixV().transpose();
  EXPECT_GT(R.determinant(), 0);
  Eigen::Matrix3Xd goals(3, n);
  for (Eigen::Index i = 0; i < n; ++i) goals.col(i) = R * (x0.col(i) - c0) + c;
  return goals;
}

TEST(Solver, AlphaOneLandsDeformedClusterOnGoals) {
  const TreeModel model = single_cluster(Eigen::Vector3d(-800, 3, 1200));
  Simulator sim(model, per_step(1.0, 0, false), calm(), 0.01, 1);
  SimState state = sim.initial_state(0);
  std::mt19937_64 rng(1);
  std::normal_distribution<double> n(0, 0.02);
  const Eigen::Quaterniond rotation(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()));
  for (Eigen::Index v = 0; v < state.positions.cols(); ++v)
    state.positions.col(v) = rotation * model.rest_positions.col(v) + Eigen::Vector3d(n(rng), n(rng), n(rng));
  state.cluster_rotations.col(0) = rotation.coeffs();
  const Eigen::Matrix3Xd goals = reference_goals(model.rest_positions, model.vertex_mass, state.positions);
  ASSERT_GT((goals - state.positions).cwiseAbs().maxCoeff(), 1e-3);  // really deformed
  sim.advance_frame(state, 1);
  // Corrections are stored as float (docs/solver.md): 1e-7 of a 2 cm move.
  EXPECT_LT((state.positions - goals).cwiseAbs().maxCoeff(), 1e-8);
}

TEST(Solver, SharedVertexTakesTheAverageOfItsGoals) {
  // Two clusters share the middle ring. Pull only the free end ring sideways: with alpha = 1
  // a vertex of the shared ring moves to the mean of its two goals (not their sum).
  ModelBuilder b;
  b.add_branch({0, 0, 0}, {0, 1, 0}, 1.0, 2, 0.05, 0.05, -1, false, 4);
  const TreeModel model = b.finish();
  Simulator sim(model, per_step(1.0, 0, false), calm(), 0.01, 1);
  SimState state = sim.initial_state(0);
  for (int k = 8; k < 12; ++k) state.positions(0, k) += 0.1;
  SimState copy = state;
  sim.advance_frame(state, 1);
  // Reference: goals of each cluster on its own, averaged.
  auto cluster_goals = [&](int first_ring, int second_ring) {
    Eigen::Matrix3Xd x0(3, 8), x(3, 8);
    x0 << model.rest_positions.middleCols(first_ring, 4), model.rest_positions.middleCols(second_ring, 4);
    x << copy.positions.middleCols(first_ring, 4), copy.positions.middleCols(second_ring, 4);
    std::vector<double> m(model.vertex_mass.begin() + first_ring, model.vertex_mass.begin() + first_ring + 4);
    m.insert(m.end(), model.vertex_mass.begin() + second_ring, model.vertex_mass.begin() + second_ring + 4);
    return reference_goals(x0, m, x);
  };
  const Eigen::Matrix3Xd lower = cluster_goals(0, 4), upper = cluster_goals(4, 8);
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d expected = 0.5 * (lower.col(4 + k) + upper.col(k));
    EXPECT_LT((state.positions.col(4 + k) - expected).norm(), 1e-9) << k;
  }
}

TEST(Solver, AttachedLeafTurnsByLeafTurnInATenMetreWind) {
  // hsm.leaf_turn is the turn of a leaf about its petiole when a 10 m/s wind blows across its
  // blade (the petiole's compliance is set from the leaf's own area and arm): on a held
  // branch, in a steady 10 m/s wind normal to the leaf's arm, the settled leaf has turned by
  // leaf_turn about its petiole vertex, at 4 and at 32 substeps.
  ModelBuilder b;
  const uint32_t r0 = b.add_ring({0, 0, 0}, {0, 1, 0}, 0.02, 6, true);
  const uint32_t r1 = b.add_ring({0, 0.3, 0}, {0, 1, 0}, 0.02, 6, true);
  const uint32_t branch = b.add_segment(r0, r1, 6, -1, 0.02, 0.3);
  b.add_leaf(branch, r1 + 1, {1, 0.3, 0.2}, 0.08);
  const TreeModel model = b.finish();
  const uint32_t a = model.leaf_attachment_vertex[0], tip = a + 2;
  const Eigen::Vector3d arm = model.rest_positions.col(tip) - model.rest_positions.col(a);
  // Across the arm and across the blade's normal: the drag's arm is the whole arm.
  WindOptions wind = steady_wind(10, arm.cross(Eigen::Vector3d::UnitY()).normalized(), 0);
  wind.turbulence_intensity = 0;
  HsmOptions options = awake();
  options.damping_ratio = 1;
  for (int substeps : {4, 32}) {
    Simulator sim(model, options, wind, 1.0 / 24, substeps);
    SimState state = sim.initial_state(0);
    advance(sim, state, 1, 240);  // 10 s: settled
    const Eigen::Vector3d now = state.positions.col(tip) - state.positions.col(a);
    const double turn = std::acos(std::clamp(now.normalized().dot(arm.normalized()), -1.0, 1.0));
    EXPECT_NEAR(turn, options.leaf_turn, 0.05 * options.leaf_turn) << substeps << " substeps";
    EXPECT_NEAR(now.norm(), arm.norm(), 1e-3 * arm.norm()) << "the leaf keeps its shape";
  }
}

TEST(Solver, AnchoredVerticesNeverMove) {
  const TreeModel model = small_tree(1);
  const WindOptions wind = steady_wind(25, Eigen::Vector3d{1, 0, 0.3}, 5);
  Simulator sim(model, awake(), wind, 1.0 / 24, 4);
  SimState state = sim.initial_state(0);
  advance(sim, state, 1, 24);
  double moved = 0;
  for (size_t v = 0; v < model.vertex_count(); ++v) {
    if (model.vertex_anchored[v]) EXPECT_EQ((state.positions.col(v) - model.rest_positions.col(v)).norm(), 0.0);
    else moved = std::max(moved, (state.positions.col(v) - model.rest_positions.col(v)).norm());
  }
  EXPECT_GT(moved, 1e-3);  // the wind did move the tree
}

TEST(Solver, TreeAtRestStaysAtRestFor100kSteps) {
  // Physical default stiffness, no wind, sleeping off (so every step really runs), far from
  // the origin to include the precision of the cluster-local frame; in both precisions (a
  // float rest offset is rounded, and the tree must not creep from it).
  const TreeModel model = small_tree(2, Eigen::Vector3d(1000, 0, -2000));
  for (Precision precision : {Precision::kDouble, Precision::kFloat}) {
    HsmOptions options = awake();
    options.precision = precision;
    Simulator sim(model, options, calm(), 1.0 / 24, 100);
    SimState state = sim.initial_state(0);
    double worst = 0;
    for (int f = 1; f <= 1000; ++f) {
      sim.advance_frame(state, f);
      worst = std::max(worst, (state.positions - model.rest_positions).cwiseAbs().maxCoeff());
    }
    EXPECT_LT(worst, 1e-6) << (precision == Precision::kFloat ? "float" : "double");
  }
}

TEST(Solver, NonFiniteValueNamesFrameSubstepAndCluster) {
  const TreeModel model = small_tree();
  HsmOptions options = awake();
  Simulator sim(model, options, calm(), 1.0 / 24, 3);
  SimState state = sim.initial_state(0);
  state.positions(1, 40) = std::numeric_limits<double>::quiet_NaN();
  try {
    sim.advance_frame(state, 7);
    FAIL() << "expected SimulationError";
  } catch (const SimulationError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("frame 7, substep 0, cluster "), std::string::npos) << message;
    EXPECT_NE(message.find("non-finite"), std::string::npos) << message;
    EXPECT_NE(message.find("(vertex 40)"), std::string::npos) << message;  // the vertex at fault, not one it spread to
  }
}

TEST(Solver, ExtremeWindAndLargeStepStayFinite) {
  const TreeModel model = small_tree(3);
  WindOptions wind;
  wind.keys = {{0, 60, {1, 0, 0}, 20}, {4, 60, {1, 0, 0}, 20}, {5, 0, {1, 0, 0}, 0}};
  for (double fps : {4.0, 24.0}) {
    HsmOptions options;
    options.sleep = false;
    Simulator sim(model, options, wind, 1.0 / fps, 1);
    SimState state = sim.initial_state(0);
    double fastest = 0;
    const int frames = static_cast<int>(30 * fps);
    bool came_apart = false;
    for (int f = 1; f <= frames && !came_apart; ++f) {
      try {
        sim.advance_frame(state, f);
      } catch (const SimulationError& e) {
        // One step (0.25 s or 1/24 s) in this gale may carry thin branches farther than 2.5
        // times the tree's size (the stress suite's limit): the runaway guard stops the bake then,
        // and the error is that, never a non-finite value.
        const std::string message = e.what();
        EXPECT_NE(message.find("more than 2.5 times the tree's size"), std::string::npos) << message;
        came_apart = true;
        continue;
      }
      fastest = std::max(fastest, state.velocities.colwise().norm().maxCoeff());
      // At one substep per frame the gale carries thin branches up to a step's worth of
      // wind (80 m/s x 0.25 s) before the clusters pull them back; at 24 fps the tree bends
      // flat at worst (a point 4.2 m from the anchor moves less than 8.4 m).
      const double bound = fps == 4.0 ? 80 * 0.25 : 8.4;
      ASSERT_LT((state.positions - model.rest_positions).colwise().norm().maxCoeff(), bound) << fps << " " << f;
    }
    if (came_apart) continue;
    EXPECT_LT(fastest, 80.0 * 1.5);  // never much faster than the air (60 m/s + 20 m/s gusts)
    // 25 s after the gale the tree is back near its rest pose.
    EXPECT_LT((state.positions - model.rest_positions).colwise().norm().maxCoeff(), 1e-2) << fps;
  }
}

TEST(Solver, DegenerateClustersStayFinite) {
  // A zero-length segment (both rings at one place), a massless cluster and a single-vertex
  // leaf; wind on.
  ModelBuilder b;
  const uint32_t r0 = b.add_ring({0, 0, 0}, {0, 1, 0}, 0.05, 4, true);
  const uint32_t r1 = b.add_ring({0, 1, 0}, {0, 1, 0}, 0.05, 4);
  const uint32_t r2 = b.add_ring({0, 1, 0}, {0, 1, 0}, 0.0, 4);  // collapsed to a point
  const uint32_t c0 = b.add_segment(r0, r1, 4, -1, 0.05, 1);
  const uint32_t c1 = b.add_segment(r1, r2, 4, c0, 0.0, 0.0);
  b.members.push_back({r2});
  b.kind.push_back(kClusterLeaf);
  b.parent.push_back(static_cast<int32_t>(c1));
  b.length.push_back(0);
  b.radius.push_back(0);
  b.area.push_back(0);
  b.mass.push_back(0);
  const TreeModel model = b.finish();
  const WindOptions wind = steady_wind(30, Eigen::Vector3d{0, 0, 1}, 10);
  HsmOptions options = awake();
  Simulator sim(model, options, wind, 1.0 / 24, 2);
  SimState state = sim.initial_state(0);
  for (int f = 1; f <= 48; ++f) ASSERT_NO_THROW(sim.advance_frame(state, f));
  EXPECT_TRUE(state.positions.allFinite());
}

// The last step of a frame predicts the next frame's first step and keeps that prediction in
// the state (SimState::predicted). A copy taken mid-bake and resumed by another simulator
// continues with the same bits; a state edited by hand with `predicted` reset is predicted
// from its positions.
TEST(Solver, ResumedAndEditedStatesArePredictedFromTheirPositions) {
  const TreeModel model = small_tree(3);
  const WindOptions wind = steady_wind(12, Eigen::Vector3d{1, 0, 0.2}, 3);
  const HsmOptions options = awake();
  Simulator whole(model, options, wind, 1.0 / 24, 4);
  SimState state = whole.initial_state(0);
  advance(whole, state, 1, 24);
  SimState checkpoint = state;
  advance(whole, state, 25, 48);
  // Resumed elsewhere: the same bits (the state holds the prediction it was written with).
  Simulator resumed(model, options, wind, 1.0 / 24, 4);
  advance(resumed, checkpoint, 25, 48);
  EXPECT_EQ((checkpoint.positions - state.positions).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ((checkpoint.velocities - state.velocities).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_GT((state.positions - model.rest_positions).cwiseAbs().maxCoeff(), 1e-3);  // it moved

  // Edited by hand: a simulator that carried a prediction and a fresh one agree exactly.
  SimState edited = state;
  edited.positions = model.rest_positions;
  edited.velocities.setZero();
  edited.predicted = false;
  SimState fresh_copy = edited;
  whole.advance_frame(edited, 49);
  Simulator fresh(model, options, wind, 1.0 / 24, 4);
  fresh.advance_frame(fresh_copy, 49);
  EXPECT_EQ((edited.positions - fresh_copy.positions).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ((edited.velocities - fresh_copy.velocities).cwiseAbs().maxCoeff(), 0.0);
}

}  // namespace
}  // namespace treeanim
