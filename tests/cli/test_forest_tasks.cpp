// Farm tasks of a forest (docs/farm.md "Shards"): balanced by cost, deterministic, every tree once.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>

#include "cli/forest_tasks.h"
#include "common/errors.h"

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

TEST(ForestTasks, ParseShard) {
  EXPECT_EQ(parse_shard("3/8").index, 3u);
  EXPECT_EQ(parse_shard("3/8").count, 8u);
  for (const char* bad : {"8/8", "1", "-1/4", "a/4", "0/0", "1/", "/4"})
    EXPECT_THROW(parse_shard(bad), InputError) << bad;
  setenv("SLURM_ARRAY_TASK_ID", "2", 1);
  EXPECT_EQ(parse_shard("auto/4").index, 2u);
  unsetenv("SLURM_ARRAY_TASK_ID");
  EXPECT_THROW(parse_shard("auto/4"), InputError);
}

}  // namespace
}  // namespace treeanim
