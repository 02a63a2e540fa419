#pragma once
// A forest split into farm tasks (docs/farm.md "Shards"): each tree's cost estimated, the trees
// dealt to tasks so that every task costs about the same, and which task a process runs.
#include <cstdint>
#include <optional>
#include <vector>

#include "bake/bake_config.h"
#include "bake/bake_log.h"
#include "scene/scene.h"

namespace treeanim {

// Seconds of one core per vertex and substep of a bake, measured on the reference machine
// (docs/farm.md "Measured here"): converts estimated costs into CPU-hours.
inline constexpr double kSecondsPerVertexStep = 8.6e-8;

// What one tree of each variant costs, from one model per variant (the first tree of it): the
// vertex count does not depend on a tree's scale, and only a stochastic grammar's seed changes it.
struct ForestEstimate {
  std::vector<uint64_t> tree_cost;   // (trees) vertices x substeps of the bake
  std::vector<double> tree_bytes;    // (trees) estimated bytes of the tree's outputs
  std::vector<size_t> tree_vertices; // (trees) vertices of the tree's variant model
  std::vector<double> tree_checkpoint_bytes;  // (trees) one checkpoint of the tree (an upper bound)
  std::vector<double> tree_record_bytes;      // (trees) one frame of its journal, velocities included
};

// Builds each used variant's model once (derivation, mesh); no simulation. Throws InputError.
ForestEstimate estimate_forest(const Scene& scene);

// Costs, tasks => the trees of each task (ascending), dealt longest first to the task with the
// least cost so far (ties: the lower index); deterministic, so every shard of a farm job agrees.
std::vector<std::vector<size_t>> assign_tasks(const std::vector<uint64_t>& cost, size_t tasks);

// A forest, a shard (none: every tree) => the trees that this process bakes, ascending, once
// every variant has grown (estimate_forest: InputError for a variant that cannot), and each of
// those trees whose seed shapes its growth (`passed`: as each is grown).
std::vector<size_t> shard_trees(const Scene& scene, const std::optional<Shard>& shard, const TreesPassed& passed);

}  // namespace treeanim
