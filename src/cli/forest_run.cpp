#include "cli/forest_run.h"

#include <cstdio>
#include <system_error>

#include "cli/bake_tree.h"
#include "cli/forest_manifest.h"
#include "cli/forest_tasks.h"
#include "common/errors.h"

namespace treeanim {

namespace fs = std::filesystem;

int run_forest(const Scene& scene, const RunRequest& request) {
  const Forest& forest = *scene.forest;
  if (request.frames)
    throw InputError("--frames " + *request.frames + ": a forest is split by its trees (--shard I/N), not by frames");
  std::vector<size_t> trees;  // this process's, ascending
  Shard shard;
  if (request.shard) {
    shard = parse_shard(*request.shard);
    trees = assign_tasks(estimate_forest(scene).tree_cost, shard.count)[shard.index];
  } else {
    for (size_t t = 0; t < forest.trees.size(); ++t) trees.push_back(t);
  }
  const bool quiet = request.verbosity == Verbosity::kQuiet;
  const fs::path checkpoints = !request.checkpoint_dir.empty() ? request.checkpoint_dir : request.out_dir / "checkpoints";
  if (!quiet && request.shard)
    std::printf("shard %zu/%zu: %zu of the forest's %zu trees\n", shard.index, shard.count, trees.size(),
                forest.trees.size());

  size_t baked = 0, skipped = 0;
  for (size_t i = 0; i < trees.size(); ++i) {
    const ForestTree& tree = forest.trees[trees[i]];
    const Scene one = tree_scene(scene, trees[i]);
    std::string why;
    if (request.resume && complete_tree_part(request.out_dir, tree.id, tree_bake_key(one), why)) {
      if (!quiet) std::printf("tree %zu/%zu %s: complete, skipped\n", i + 1, trees.size(), tree.id.c_str());
      ++skipped;
      continue;
    }
    if (!quiet) {
      std::printf("tree %zu/%zu %s (%s, seed %llu) at (%.2f, %.2f, %.2f)\n", i + 1, trees.size(), tree.id.c_str(),
                  forest.variants[tree.variant].name.c_str(), static_cast<unsigned long long>(tree.seed),
                  tree.position.x(), tree.position.y(), tree.position.z());
      std::fflush(stdout);
    }
    RunRequest own = request;
    own.checkpoint_dir = checkpoints / tree.id;
    const TreePlacement placement = make_tree_placement(tree.position, tree.rotation);
    const TreeBakeResult result = bake_tree(one, own, &placement);
    if (result.exit_code != 0) return result.exit_code;
    write_tree_part(request.out_dir, scene, trees[i], one, result);
    // Whole trees are the unit of a forest's restart: a finished tree's checkpoints are spent.
    std::error_code ignored;
    if (request.checkpoint_every > 0) fs::remove_all(own.checkpoint_dir, ignored);
    ++baked;
  }
  if (request.shard) {
    if (!quiet)
      std::printf("shard %zu/%zu: %zu trees baked, %zu complete before; once every shard is done: treeanim farm "
                  "gather %s%s%s\n",
                  shard.index, shard.count, baked, skipped, request.scene.string().c_str(),
                  request.out_dir.empty() ? "" : " -o ", request.out_dir.string().c_str());
    return 0;
  }
  const GatherReport report = gather_forest(scene, request.out_dir);
  if (!report.missing.empty())  // a file removed while the forest baked
    throw OutputError(forest.trees[report.missing.front()].id + ": " + report.reasons.front());
  if (!quiet)
    std::printf("forest: %zu trees (%zu baked, %zu complete before); manifest %s\n", forest.trees.size(), baked,
                skipped, forest_manifest_path(request.out_dir).string().c_str());
  return 0;
}

}  // namespace treeanim
