#include "bake/bake_forest.h"

#include <omp.h>

#include <algorithm>
#include <system_error>

#include "bake/bake_plan.h"
#include "bake/bake_start.h"
#include "bake/bake_tree.h"
#include "bake/checkpoint.h"
#include "bake/forest_manifest.h"
#include "bake/signals.h"
#include "bake/thread_governor.h"
#include "common/errors.h"
#include "files/output_lock.h"
#include "formats/outputs.h"

namespace treeanim {

namespace fs = std::filesystem;

namespace {

// Every file the forest writes into `targets`: the manifest and its stage and page, each tree's
// outputs and part, and the checkpoints of the trees that write now. `written(t)`: tree t bakes
// now (its targets are looked at as well as counted); the others only keep their files from
// any other writer.
template <typename Written>
void add_forest_files(const Scene& scene, const BakeConfig& config, bool manifest_written, Written written,
                      OutputTargets& targets, const TreesPassed& passed) {
  add_forest_targets(scene, config.out_dir, targets, manifest_written);
  for (size_t t = 0; t < scene.forest->trees.size(); ++t) {
    passed("checking outputs", t + 1, scene.forest->trees.size());
    const std::string& id = scene.forest->trees[t].id;
    const Scene one = tree_scene(scene, t);
    const bool writes = written(t, one);
    const BakePlan plan = plan_frames(one, tree_bake_config(config, id));
    targets.add_outputs(one.outputs, config.out_dir, plan.written.first, plan.written.count(), "tree " + id, writes);
    targets.add_file(tree_part_path(config.out_dir, id), "the part of tree " + id, writes);
    // A complete tree's folder too: its spent checkpoints are removed from it.
    if (plan.checkpoints.every > 0) {
      const std::string checkpoints = "the checkpoints of tree " + id;
      targets.add_folder(plan.checkpoints.dir, checkpoints);
      check_checkpoint_folder(plan.checkpoints.dir);
      if (writes) targets.add_file(journal_path(plan.checkpoints.dir, plan.written.first), checkpoints);
    }
  }
}

// Which of `trees` are complete already (--resume: their parts say so); and, before the first
// tree grows, every file the forest writes looked at (OutputTargets): each written by one
// writer and absent or a regular file, and every folder they go into able to take a file.
// Found only as each tree is baked, a later tree's bad target would fail the forest after
// earlier trees were written. Every tree of the forest is counted for "one writer" (a tree of
// another shard, or a complete one, keeps its files); the trees baked here are looked at and probed.
std::vector<bool> look_before_baking(const Scene& scene, const BakeConfig& config, const std::vector<size_t>& trees,
                                     const TreesPassed& passed) {
  std::vector<size_t> position(scene.forest->trees.size(), trees.size());  // index into `trees`, or none
  for (size_t i = 0; i < trees.size(); ++i) position[trees[i]] = i;
  std::vector<bool> complete(trees.size(), false);
  OutputTargets targets;
  add_forest_files(scene, config, !config.shard, [&](size_t t, const Scene& one) {
    const size_t i = position[t];
    if (i == trees.size()) return false;
    std::string why;
    complete[i] = config.checkpoints.resume &&
                  complete_tree_part(config.out_dir, scene.forest->trees[t].id, bake_key(one, config.generator), why);
    return !complete[i];
  }, targets, passed);
  MadeFolders made;  // kept once every folder takes a file: the trees write there
  try {
    targets.probe(made);
  } catch (...) {
    made.undo();
    throw;
  }
  return complete;
}

}  // namespace

void check_forest_writers(const Scene& scene, const TreesPassed& passed) {
  OutputTargets targets;
  // The manifest goes where -o puts it, which validate and info are not given (a scene named
  // forest.json is its own folder's manifest path): it only keeps its name from the trees.
  add_forest_files(scene, BakeConfig{}, false, [](size_t, const Scene&) { return true; }, targets, passed);
}

ForestBakeResult bake_forest(const Scene& scene, const BakeConfig& config, const std::vector<size_t>& trees,
                             const BakeLog& log) {
  const Forest& forest = *scene.forest;
  // A whole forest writes the manifest and every part: a second one into the same folder is
  // refused before it looks at anything (shards of one forest share it, each with trees of its own).
  OutputLocks manifest;
  MadeFolders made;  // the manifest's folder, for its lock
  std::vector<bool> complete;
  try {
    const fs::path manifest_path = forest_manifest_path(config.out_dir);
    std::error_code error;
    if (!config.shard && !manifest_path.parent_path().empty()) made.make(manifest_path.parent_path(), error);
    if (!config.shard && !error) manifest.lock(manifest_path);
    complete = look_before_baking(scene, config, trees, log.trees_passed);
  } catch (...) {
    manifest.release();
    made.undo();
    throw;
  }
  ForestBakeResult result;
  // A whole forest that rewrites a tree first removes the manifest of the one before: killed
  // halfway, it left a manifest that called old and new trees one complete forest.
  if (!config.shard && std::find(complete.begin(), complete.end(), false) != complete.end()) {
    const DeferredInterrupts deferred;
    remove_forest_files(config.out_dir);
  }
  // One team for the forest: what other work leaves it carries from tree to tree.
  if (config.threads > 0) omp_set_num_threads(config.threads);
  ThreadGovernor governor(omp_get_max_threads(), log.team_resized);
  for (size_t i = 0; i < trees.size(); ++i) {
    // A signal while the last tree finished: the trees baked so far stay whole.
    if (const int signal_number = pending_signal()) {
      log.interrupted(signal_number, -1);
      result.exit_code = interrupted_exit_code(signal_number);
      return result;
    }
    log.forest_tree(i, trees.size(), trees[i], complete[i]);
    const ForestTree& tree = forest.trees[trees[i]];
    const BakeConfig own = tree_bake_config(config, tree.id);
    // Whole trees are the unit of a forest's restart: a finished tree's checkpoints are spent
    // (a bake killed between its part and their removal left them).
    if (complete[i]) {
      if (config.checkpoints.every > 0) remove_spent_checkpoints(own.checkpoints.dir);
      ++result.skipped;
      continue;
    }
    const Scene one = tree_scene(scene, trees[i]);
    const TreePlacement placement = make_tree_placement(tree.position, tree.rotation);
    const TreeBakeResult baked = bake_tree(one, own, &placement, log, &governor);
    if (baked.exit_code != 0) {
      result.exit_code = baked.exit_code;
      return result;
    }
    {
      const DeferredInterrupts deferred;  // the part is written whole, the spent checkpoints all removed
      write_tree_part(config, scene, trees[i], one, baked);
      if (config.checkpoints.every > 0) remove_spent_checkpoints(own.checkpoints.dir);
    }
    ++result.baked;
  }
  if (config.shard) return result;
  const DeferredInterrupts deferred;  // the manifest is written whole
  const GatherReport report =
      gather_forest(scene, config.out_dir, config.generator, config.checkpoints.every > 0 ? config.checkpoints.dir : "");
  if (!report.missing.empty())  // a file removed while the forest baked
    throw OutputError(forest.trees[report.missing.front()].id + ": " + report.reasons.front());
  return result;
}

}  // namespace treeanim
