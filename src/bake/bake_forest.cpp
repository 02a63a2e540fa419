#include "bake/bake_forest.h"

#include <system_error>

#include "bake/bake_tree.h"
#include "bake/forest_manifest.h"
#include "bake/signals.h"
#include "common/errors.h"

namespace treeanim {

namespace fs = std::filesystem;

ForestBakeResult bake_forest(const Scene& scene, const BakeConfig& config, const std::vector<size_t>& trees,
                             const BakeLog& log) {
  const Forest& forest = *scene.forest;
  ForestBakeResult result;
  for (size_t i = 0; i < trees.size(); ++i) {
    // A signal while the last tree finished: the trees baked so far stay whole.
    if (const int signal_number = pending_signal()) {
      log.interrupted(signal_number, -1);
      result.exit_code = interrupted_exit_code(signal_number);
      return result;
    }
    const ForestTree& tree = forest.trees[trees[i]];
    const Scene one = tree_scene(scene, trees[i]);
    std::string why;
    const bool complete = config.checkpoints.resume &&
                          complete_tree_part(config.out_dir, tree.id, bake_key(one, config.generator), why);
    log.forest_tree(i, trees.size(), trees[i], complete);
    if (complete) {
      ++result.skipped;
      continue;
    }
    const BakeConfig own = tree_bake_config(config, tree.id);
    const TreePlacement placement = make_tree_placement(tree.position, tree.rotation);
    const TreeBakeResult baked = bake_tree(one, own, &placement, log);
    if (baked.exit_code != 0) {
      result.exit_code = baked.exit_code;
      return result;
    }
    {
      const DeferredInterrupts deferred;  // the part is written whole, the spent checkpoints all removed
      write_tree_part(config, scene, trees[i], one, baked);
      // Whole trees are the unit of a forest's restart: a finished tree's checkpoints are spent.
      std::error_code ignored;
      if (config.checkpoints.every > 0) fs::remove_all(own.checkpoints.dir, ignored);
    }
    ++result.baked;
  }
  if (config.shard) return result;
  const DeferredInterrupts deferred;  // the manifest is written whole
  const GatherReport report = gather_forest(scene, config.out_dir, config.generator);
  if (!report.missing.empty())  // a file removed while the forest baked
    throw OutputError(forest.trees[report.missing.front()].id + ": " + report.reasons.front());
  return result;
}

}  // namespace treeanim
