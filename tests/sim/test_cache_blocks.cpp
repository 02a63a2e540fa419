// The step in cache blocks (cache_blocks.cpp) is the separate passes in another order: its
// blocks partition the clusters and the vertices as the step needs, and a bake in blocks has
// the bytes of one without, frame by frame, through wind, calm and sleep, in both precisions
// and at any thread count; it fails where and as the separate passes fail.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <limits>
#include <string>
#include <vector>

#include "common/errors.h"
#include "grown_tree.h"
#include "same_state.h"
#include "sim/simulator.h"
#include "sim/solver_model.h"

namespace treeanim {
namespace {

using testing::expect_same_state;
using testing::grown_tree;
using testing::same_bytes;

constexpr size_t kSmallBlocks = 512;  // memberships: a dozen blocks on the test trees
constexpr int kBlockFrames = 72;

TEST(CacheBlocks, PartitionTheClustersAndVerticesAsTheStepNeeds) {
  const TreeModel tree = grown_tree(6, 2, 2);
  const SolverModel<float> model(tree, HsmOptions{}, WindOptions{}, 1.0 / 24, 2, kSmallBlocks);
  const size_t blocks = model.block_cluster_offsets.size() - 1;
  ASSERT_GE(blocks, 4u);
  ASSERT_FALSE(model.pinned_leaf_clusters.empty());
  // Every cluster in one block; the unpinned ascending, then the pinned leaves, each in its
  // branch's block.
  std::vector<uint32_t> block_of(model.C, kNone);
  std::vector<uint8_t> pinned(model.C, 0);
  for (uint32_t c : model.pinned_leaf_clusters) pinned[c] = 1;
  for (size_t b = 0; b < blocks; ++b) {
    uint32_t memberships = 0;
    for (uint32_t k = model.block_cluster_offsets[b]; k < model.block_cluster_offsets[b + 1]; ++k) {
      const uint32_t c = model.block_clusters[k];
      ASSERT_EQ(block_of[c], kNone) << "cluster " << c << " in two blocks";
      block_of[c] = static_cast<uint32_t>(b);
      memberships += tree.cluster_offsets[c + 1] - tree.cluster_offsets[c];
      if (k > model.block_cluster_offsets[b]) {
        const uint32_t before = model.block_clusters[k - 1];
        EXPECT_TRUE(pinned[before] <= pinned[c] && (pinned[before] != pinned[c] || before < c)) << b;
      }
    }
    EXPECT_EQ(model.block_membership_offsets[b + 1] - model.block_membership_offsets[b], memberships);
  }
  for (size_t c = 0; c < model.C; ++c) EXPECT_NE(block_of[c], kNone) << "cluster " << c << " in no block";
  for (uint32_t c : model.pinned_leaf_clusters)
    EXPECT_EQ(block_of[c], block_of[tree.member_cluster[model.all_attached.cluster_pin_slot[c]]]) << c;
  // Every vertex in one segment: a block's holds vertices of its clusters alone, the
  // border's (entry B) those of clusters in two blocks or in none.
  std::vector<uint32_t> vertex_block(model.V, kNone);
  for (size_t b = 0; b <= blocks; ++b) {
    for (uint32_t i = model.block_segment_offsets[b]; i < model.block_segment_offsets[b + 1]; ++i) {
      const VertexSegment& segment = model.block_segments[i];
      ASSERT_LT(segment.begin, segment.end);
      if (i > model.block_segment_offsets[b]) {
        EXPECT_LT(model.block_segments[i - 1].end, segment.begin);
      }
      for (uint32_t v = segment.begin; v < segment.end; ++v) {
        ASSERT_EQ(vertex_block[v], kNone) << "vertex " << v << " in two segments";
        vertex_block[v] = static_cast<uint32_t>(b);
      }
    }
  }
  size_t border = 0;
  std::vector<uint8_t> border_cluster(model.C, 0);
  for (size_t v = 0; v < model.V; ++v) {
    ASSERT_NE(vertex_block[v], kNone) << "vertex " << v << " in no segment";
    std::vector<uint32_t> holding;
    for (uint32_t s = tree.vertex_cluster_offsets[v]; s < tree.vertex_cluster_offsets[v + 1]; ++s)
      holding.push_back(block_of[tree.member_cluster[tree.vertex_memberships[s]]]);
    const bool one_block =
        !holding.empty() && std::all_of(holding.begin(), holding.end(), [&](uint32_t b) { return b == holding[0]; });
    EXPECT_EQ(vertex_block[v], one_block ? holding[0] : blocks) << "vertex " << v;
    if (one_block) continue;
    ++border;
    for (uint32_t s = tree.vertex_cluster_offsets[v]; s < tree.vertex_cluster_offsets[v + 1]; ++s)
      border_cluster[tree.member_cluster[tree.vertex_memberships[s]]] = 1;
  }
  EXPECT_GT(border, 0u);
  EXPECT_LT(border, model.V / 10);
  // Every cluster's loads summed once: by its block, or after the border when it holds a
  // border vertex.
  std::vector<uint32_t> loaded_by(model.C, kNone);
  for (size_t b = 0; b <= blocks; ++b) {
    for (uint32_t i = model.block_load_offsets[b]; i < model.block_load_offsets[b + 1]; ++i) {
      const uint32_t c = model.block_load_clusters[i];
      ASSERT_EQ(loaded_by[c], kNone) << "cluster " << c << " summed twice";
      loaded_by[c] = static_cast<uint32_t>(b);
    }
  }
  for (size_t c = 0; c < model.C; ++c) EXPECT_EQ(loaded_by[c], border_cluster[c] ? blocks : block_of[c]) << c;
  // No blocks: for block_memberships 0, and with leaves that detach.
  EXPECT_TRUE(SolverModel<float>(tree, HsmOptions{}, WindOptions{}, 1.0 / 24, 2, 0).block_cluster_offsets.empty());
  HsmOptions detaching;
  detaching.leaf_detach_force = 0.05;
  EXPECT_TRUE(
      SolverModel<float>(tree, detaching, WindOptions{}, 1.0 / 24, 2, kSmallBlocks).block_cluster_offsets.empty());
}

template <typename Real>
void expect_same_prediction(const StepPrediction<Real>& expected, const StepPrediction<Real>& actual) {
  EXPECT_TRUE(same_bytes(expected.offset, actual.offset));
  EXPECT_TRUE(same_bytes(expected.velocity, actual.velocity));
  EXPECT_TRUE(same_bytes(expected.drag_force, actual.drag_force));
  EXPECT_TRUE(same_bytes(expected.goal, actual.goal));
  EXPECT_TRUE(same_bytes(expected.damping_offset, actual.damping_offset));
  EXPECT_TRUE(same_bytes(expected.damping_compliance, actual.damping_compliance));
}

TEST(CacheBlocks, BakeHasTheBytesOfTheSeparatePasses) {
  // Gusts, calm until the tree sleeps (heavily damped, coarse thresholds), gusts that wake it;
  // with and without the beam; and a bake resumed from a frame in a fresh simulator in blocks.
  const TreeModel tree = grown_tree(7, 2, 2);  // large enough to run on two threads
  ASSERT_GE(tree.membership_count(), kParallelMemberships);
  WindOptions wind = testing::gust_then_calm(12, 0.2, 0.4);
  wind.keys.push_back({2.0, 0, {1, 0, 0.2}, 0});
  wind.keys.push_back({2.1, 12, {1, 0, 0.2}, 3.6});
  const int saved_threads = omp_get_max_threads();
  for (Precision precision : {Precision::kFloat, Precision::kDouble})
    for (bool beam : {true, false})
      for (int threads : {1, 2}) {
        SCOPED_TRACE(std::string(precision == Precision::kFloat ? "float" : "double") + (beam ? ", beam, " : ", no beam, ") +
                     std::to_string(threads) + " threads");
        omp_set_num_threads(threads);
        HsmOptions options;
        options.precision = precision;
        options.global_matching = beam;
        options.damping_ratio = 1;
        options.sleep_velocity = 0.01;
        options.sleep_distance = 0.01;
        Simulator passes(tree, options, wind, 1.0 / 24, 3, 0), blocks(tree, options, wind, 1.0 / 24, 3, kSmallBlocks);
        SimState expected = passes.initial_state(0), actual = blocks.initial_state(0);
        bool slept = false;
        SimState saved;
        for (int f = 1; f <= kBlockFrames; ++f) {
          passes.advance_frame(expected, f);
          blocks.advance_frame(actual, f);
          expect_same_state(expected, actual, f);
          if (precision == Precision::kFloat)
            expect_same_prediction(expected.prediction<float>(), actual.prediction<float>());
          else
            expect_same_prediction(expected.prediction<double>(), actual.prediction<double>());
          slept |= std::any_of(actual.island_asleep.begin(), actual.island_asleep.end(), [](uint8_t a) { return a; });
          if (f == 20) saved = actual;
        }
        EXPECT_TRUE(slept || !beam);  // the beam's damping puts the tree to sleep in the calm
        Simulator fresh(tree, options, wind, 1.0 / 24, 3, kSmallBlocks);
        for (int f = 21; f <= kBlockFrames; ++f) fresh.advance_frame(saved, f);
        expect_same_state(expected, saved, kBlockFrames);
      }
  omp_set_num_threads(saved_threads);
}

// The message a bake in `block_memberships` throws when `spoil` spoils its state after frame 2.
template <typename Spoil>
std::string failure(const TreeModel& tree, size_t block_memberships, Spoil spoil) {
  HsmOptions options;
  options.sleep = false;
  Simulator sim(tree, options, testing::gust_then_calm(12, 10, 11), 1.0 / 24, 3, block_memberships);
  SimState state = sim.initial_state(0);
  for (int f = 1; f <= 2; ++f) sim.advance_frame(state, f);
  spoil(state);
  try {
    for (int f = 3; f <= 6; ++f) sim.advance_frame(state, f);
  } catch (const SimulationError& e) {
    return e.what();
  }
  return "no failure";
}

TEST(CacheBlocks, AFailureIsReportedAsTheSeparatePassesReportIt) {
  const TreeModel tree = grown_tree(6, 2, 2);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const uint32_t v = static_cast<uint32_t>(tree.vertex_count() / 2);
  // A predicted position not finite: the fit of its clusters fails; a predicted velocity: its
  // correction; a velocity in the state that the next frame predicts from.
  auto offset = [&](SimState& s) { s.prediction<double>().offset(v, 1) = nan; };
  auto velocity = [&](SimState& s) { s.prediction<double>().velocity(v, 0) = nan; };
  auto state = [&](SimState& s) {
    s.velocities(2, v) = nan;
    s.predicted = false;
  };
  const std::string spoilt[] = {failure(tree, 0, offset), failure(tree, 0, velocity), failure(tree, 0, state)};
  EXPECT_NE(spoilt[0].find("the shape match produced a non-finite"), std::string::npos) << spoilt[0];
  EXPECT_NE(spoilt[1].find("(vertex " + std::to_string(v) + "): non-finite"), std::string::npos) << spoilt[1];
  EXPECT_NE(spoilt[2].find("(vertex " + std::to_string(v) + "): non-finite"), std::string::npos) << spoilt[2];
  EXPECT_EQ(failure(tree, kSmallBlocks, offset), spoilt[0]);
  EXPECT_EQ(failure(tree, kSmallBlocks, velocity), spoilt[1]);
  EXPECT_EQ(failure(tree, kSmallBlocks, state), spoilt[2]);
}

}  // namespace
}  // namespace treeanim
