#include "bake/bake_forest.h"

#include <system_error>

#include "bake/bake_plan.h"
#include "bake/bake_tree.h"
#include "bake/forest_manifest.h"
#include "bake/signals.h"
#include "common/errors.h"
#include "files/text_output.h"
#include "formats/outputs.h"

namespace treeanim {

namespace fs = std::filesystem;

namespace {

// Which of `trees` are complete already (--resume: their parts say so), and for the others
// what looking finds, before the first tree grows: OutputSet's first check of each tree's
// outputs, and its part's and the manifest's paths (InputError, nothing created). Found only as
// each tree is baked, a later tree's bad target would fail the forest after earlier trees were
// written.
std::vector<bool> look_before_baking(const Scene& scene, const BakeConfig& config, const std::vector<size_t>& trees) {
  std::vector<bool> complete(trees.size());
  for (size_t i = 0; i < trees.size(); ++i) {
    const std::string& id = scene.forest->trees[trees[i]].id;
    const Scene one = tree_scene(scene, trees[i]);
    std::string why;
    complete[i] = config.checkpoints.resume &&
                  complete_tree_part(config.out_dir, id, bake_key(one, config.generator), why);
    if (complete[i]) continue;
    const FrameRange written = plan_bake(one, config).written;
    check_output_targets(one.outputs, config.out_dir, written.first, written.count());
    check_text_output_target(tree_part_path(config.out_dir, id));
  }
  if (!config.shard) check_forest_targets(scene, config.out_dir);
  return complete;
}

}  // namespace

ForestBakeResult bake_forest(const Scene& scene, const BakeConfig& config, const std::vector<size_t>& trees,
                             const BakeLog& log) {
  const Forest& forest = *scene.forest;
  const std::vector<bool> complete = look_before_baking(scene, config, trees);
  ForestBakeResult result;
  for (size_t i = 0; i < trees.size(); ++i) {
    // A signal while the last tree finished: the trees baked so far stay whole.
    if (const int signal_number = pending_signal()) {
      log.interrupted(signal_number, -1);
      result.exit_code = interrupted_exit_code(signal_number);
      return result;
    }
    log.forest_tree(i, trees.size(), trees[i], complete[i]);
    if (complete[i]) {
      ++result.skipped;
      continue;
    }
    const ForestTree& tree = forest.trees[trees[i]];
    const Scene one = tree_scene(scene, trees[i]);
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
