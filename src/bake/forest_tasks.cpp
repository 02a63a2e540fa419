#include "bake/forest_tasks.h"

#include <algorithm>
#include <numeric>
#include <queue>

#include "bake/checkpoint.h"
#include "bake/frame_journal.h"
#include "bake/prepare_tree.h"
#include "common/errors.h"
#include "lsystem/lsystem.h"
#include "formats/output_estimate.h"
#include "sim/particle_model.h"

namespace treeanim {

ForestEstimate estimate_forest(const Scene& scene) {
  const Forest& forest = *scene.forest;
  const long long steps = scene.time.frames * scene.time.substeps;
  std::vector<uint64_t> variant_cost(forest.variants.size(), 0);
  std::vector<double> variant_bytes(forest.variants.size(), 0);
  std::vector<size_t> variant_vertices(forest.variants.size(), 0);
  std::vector<double> variant_checkpoint(forest.variants.size(), 0), variant_record(forest.variants.size(), 0);
  std::vector<bool> built(forest.variants.size(), false);
  for (size_t t = 0; t < forest.trees.size(); ++t) {
    const uint32_t v = forest.trees[t].variant;
    if (built[v]) continue;
    built[v] = true;
    const Scene one = tree_scene(scene, t);
    const PreparedTree tree = prepare_tree(one);
    variant_vertices[v] = tree.model.vertex_count();
    variant_record[v] = double(journal_record_bytes({"", 0, tree.model.vertex_count(), tree.model.leaf_count(), true}));
    // With hsm.particles "samples" the solver moves the samples (and a checkpoint holds them),
    // and the mesh is skinned once a frame: costed as one step of its vertices a frame.
    const bool sampled = one.hsm.particles == ParticleMode::kSamples;
    const TreeModel simulated = sampled ? sample_tree_model(tree.model) : TreeModel();
    const TreeModel& moved = sampled ? simulated : tree.model;
    variant_checkpoint[v] = estimated_checkpoint_bytes(moved.vertex_count(), moved.cluster_count(), moved.leaf_count());
    variant_cost[v] = uint64_t(moved.vertex_count()) * uint64_t(steps) +
                      (sampled ? uint64_t(tree.model.vertex_count()) * uint64_t(scene.time.frames) : 0);
    for (const OutputOptions& output : one.outputs)
      variant_bytes[v] += estimated_output_bytes(output, tree.model.vertex_count(), tree.model.triangle_count(),
                                                 tree.model.cluster_count(), scene.time.frames);
  }
  // A variant no tree uses is not grown, but its grammar and view file are read: a slip in
  // them is bad input now, not when a later scene draws the variant.
  for (size_t v = 0; v < forest.variants.size(); ++v)
    if (!built[v]) load_grammar(forest.variants[v].lsystem, load_view(forest.variants[v].lsystem));
  ForestEstimate estimate;
  for (const ForestTree& tree : forest.trees) {
    estimate.tree_cost.push_back(variant_cost[tree.variant]);
    estimate.tree_bytes.push_back(variant_bytes[tree.variant]);
    estimate.tree_vertices.push_back(variant_vertices[tree.variant]);
    estimate.tree_checkpoint_bytes.push_back(variant_checkpoint[tree.variant]);
    estimate.tree_record_bytes.push_back(variant_record[tree.variant]);
  }
  return estimate;
}

std::vector<std::vector<size_t>> assign_tasks(const std::vector<uint64_t>& cost, size_t tasks) {
  std::vector<size_t> order(cost.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return cost[a] > cost[b]; });
  using Load = std::pair<uint64_t, size_t>;  // (cost so far, task): the least first, ties by task
  std::priority_queue<Load, std::vector<Load>, std::greater<Load>> least;
  for (size_t k = 0; k < tasks; ++k) least.emplace(0, k);
  std::vector<std::vector<size_t>> assigned(tasks);
  for (size_t tree : order) {
    auto [load, task] = least.top();
    least.pop();
    assigned[task].push_back(tree);
    least.emplace(load + cost[tree], task);
  }
  for (auto& trees : assigned) std::sort(trees.begin(), trees.end());
  return assigned;
}

namespace {

// The listed trees of variants whose growth depends on the seed (seed_shapes_growth), each grown
// from its own seed: what a tree's seed makes the grammar do (pass lsystem.max_modules, divide by
// zero) is bad input before the first tree's files are written, not after. A variant that every
// seed grows alike grew in estimate_forest.
void grow_seeded_trees(const Scene& scene, const std::vector<size_t>& trees, const TreesPassed& passed) {
  const Forest& forest = *scene.forest;
  std::vector<int> seeded(forest.variants.size(), -1);  // -1: not asked yet
  for (size_t i = 0; i < trees.size(); ++i) {
    passed("growing the trees whose seed shapes them", i + 1, trees.size());
    const size_t t = trees[i];
    int& variant = seeded[forest.trees[t].variant];
    if (variant < 0) variant = seed_shapes_growth(forest.variants[forest.trees[t].variant].lsystem) ? 1 : 0;
    if (!variant) continue;  // a tree's scene is made only to grow it (a million trees)
    const Scene one = tree_scene(scene, t);
    try {
      grow_skeleton(one.lsystem, nullptr);
    } catch (const InputError& e) {
      throw InputError("tree " + forest.trees[t].id + " (L-system seed " + std::to_string(one.lsystem.seed) + "): " + e.what());
    }
  }
}

}  // namespace

std::vector<size_t> shard_trees(const Scene& scene, const std::optional<Shard>& shard, const TreesPassed& passed) {
  // Every variant a tree uses grows here, with or without shards, and every tree whose seed
  // shapes it: a later tree's bad grammar, view or leaf mesh is bad input before the first tree's
  // files are written. A variant no tree uses is read, not grown (estimate_forest).
  const ForestEstimate estimate = estimate_forest(scene);
  std::vector<size_t> trees(scene.forest->trees.size());
  std::iota(trees.begin(), trees.end(), size_t{0});
  if (shard) trees = assign_tasks(estimate.tree_cost, shard->count)[shard->index];
  grow_seeded_trees(scene, trees, passed);
  return trees;
}

}  // namespace treeanim
