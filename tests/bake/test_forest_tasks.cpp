// Farm tasks of a forest (docs/farm.md "Shards"): balanced by cost, deterministic, every tree once.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>

#include "bake/forest_tasks.h"

namespace treeanim {
namespace {

TEST(ForestTasks, EveryTreeOnceAndBalanced) {
  std::vector<uint64_t> cost;
  for (int t = 0; t < 1000; ++t) cost.push_back(t % 3 == 0 ? 5000 : t % 3 == 1 ? 1200 : 300);  // three variants
  const auto tasks = assign_tasks(cost, 16);
  ASSERT_EQ(tasks.size(), 16u);
  std::vector<size_t> seen;
  uint64_t most = 0, least = UINT64_MAX, total = 0;
  for (const auto& trees : tasks) {
    EXPECT_TRUE(std::is_sorted(trees.begin(), trees.end()));
    uint64_t sum = 0;
    for (size_t t : trees) sum += cost[t];
    most = std::max(most, sum);
    least = std::min(least, sum);
    total += sum;
    seen.insert(seen.end(), trees.begin(), trees.end());
  }
  std::sort(seen.begin(), seen.end());
  std::vector<size_t> all(1000);
  std::iota(all.begin(), all.end(), size_t{0});
  EXPECT_EQ(seen, all);
  // Longest first: no task exceeds the mean by more than the cheapest tree's cost.
  EXPECT_LE(most - least, 300u);
  EXPECT_LE(double(most), double(total) / 16 + 300);
  EXPECT_EQ(assign_tasks(cost, 16), tasks);  // every shard computes the same split
}

TEST(ForestTasks, MoreTasksThanTrees) {
  const auto tasks = assign_tasks({10, 20, 30}, 5);
  EXPECT_EQ(tasks[0], std::vector<size_t>{2});
  EXPECT_EQ(tasks[1], std::vector<size_t>{1});
  EXPECT_EQ(tasks[2], std::vector<size_t>{0});
  EXPECT_TRUE(tasks[3].empty());
}

// Five trees of two variants whose costs differ by their vertex counts.
Scene forest_scene() {
  return load_scene_text(R"({"lsystem": {"axiom": "FFFF", "iterations": 0}, "forest": {
      "variants": [{"name": "tall"}, {"name": "short", "lsystem": {"axiom": "F", "iterations": 0}}],
      "trees": [{"id": "a", "variant": "tall", "position": [0, 0, 0]},
                {"id": "b", "variant": "short", "position": [3, 0, 0]},
                {"id": "c", "variant": "short", "position": [6, 0, 0]},
                {"id": "d", "variant": "tall", "position": [9, 0, 0]},
                {"id": "e", "variant": "short", "position": [12, 0, 0]}]},
    "outputs": [{"format": "hdf5", "path": "{tree}.h5"}]})",
                         "forest.json", "/scenes", {});
}

TEST(ForestTasks, ShardTreesSplitTheForest) {
  const Scene scene = forest_scene();
  std::vector<size_t> passed;  // each tree as the pass over the shard's trees reaches it
  const TreesPassed count = [&](const char*, size_t done, size_t total) {
    EXPECT_EQ(total, 5u);
    passed.push_back(done);
  };
  EXPECT_EQ(shard_trees(scene, std::nullopt, count), (std::vector<size_t>{0, 1, 2, 3, 4}));
  EXPECT_EQ(passed, (std::vector<size_t>{1, 2, 3, 4, 5}));
  const TreesPassed none = [](const char*, size_t, size_t) {};
  const ForestEstimate estimate = estimate_forest(scene);
  EXPECT_GT(estimate.tree_cost[0], estimate.tree_cost[1]);
  EXPECT_EQ(estimate.tree_cost[0], estimate.tree_cost[3]);
  // Longest first (a, d), then each short tree to the task with less so far, ties to task 0.
  EXPECT_EQ(shard_trees(scene, Shard{0, 2}, none), (std::vector<size_t>{0, 1, 4}));
  EXPECT_EQ(shard_trees(scene, Shard{1, 2}, none), (std::vector<size_t>{2, 3}));
}

}  // namespace
}  // namespace treeanim
