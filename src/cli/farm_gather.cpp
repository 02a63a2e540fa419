// treeanim farm gather: every tree complete => OUT/forest.json; else what is missing, by task.
#include <cstdio>
#include <map>

#include "bake/forest_manifest.h"
#include "bake/forest_tasks.h"
#include "cli/commands.h"
#include "cli/shell_words.h"
#include "common/errors.h"
#include "common/message_text.h"

namespace treeanim {

int farm_gather_command(const FarmRequest& request) {
  const Scene scene = load_scene(request.scene, request.overrides);
  if (!scene.forest) throw InputError(request.scene.string() + ": no /forest: farm gather collects a forest's trees");
  const Forest& forest = *scene.forest;
  OutputTargets targets;  // a folder where the manifest goes is bad input, as for run
  add_forest_targets(scene, request.out_dir, targets);
  // The tasks' checkpoints, in the output folder (farm_submit.cpp).
  const GatherReport report =
      gather_forest(scene, request.out_dir, treeanim_generator(), checkpoint_folder(request.out_dir, {}));
  if (report.missing.empty()) {
    std::printf("forest: all %zu trees complete; manifest %s\n", forest.trees.size(),
                printable_text(forest_manifest_path(request.out_dir).string()).c_str());
    return 0;
  }
  if (report.other_scene)
    throw InputError(tree_part_path(request.out_dir, forest.trees[0].id).parent_path().string() +
                     ": every tree's part is of another scene or treeanim version than " + request.scene.string() +
                     (request.overrides.empty() ? "" : " with its --set") +
                     ": gather with the scene and --set the forest was baked with (its files are left as they are), "
                     "or bake this scene first");
  std::map<size_t, std::vector<size_t>> by_task;  // task => indices into report.missing
  std::vector<size_t> task_of(forest.trees.size(), 0);
  if (request.tasks > 0) {
    const auto tasks = assign_tasks(estimate_forest(scene).tree_cost, request.tasks);
    for (size_t k = 0; k < tasks.size(); ++k)
      for (size_t t : tasks[k]) task_of[t] = k;
  }
  for (size_t m = 0; m < report.missing.size(); ++m) by_task[task_of[report.missing[m]]].push_back(m);
  std::fprintf(stderr, "treeanim: %zu of %zu trees are not complete; %s not written%s\n", report.missing.size(),
               forest.trees.size(), printable_text(forest_manifest_path(request.out_dir).string()).c_str(),
               report.removed_stale ? " (the earlier one, which no longer describes the trees, removed)" : "");
  for (const auto& [task, missing] : by_task) {
    if (request.tasks > 0) {
      std::fprintf(stderr, "  task %zu of %zu", task, request.tasks);
      if (!request.logs.empty())
        std::fprintf(stderr, " (log %s)", printable_text((request.logs / ("task-" + std::to_string(task) + ".log")).string()).c_str());
      std::fprintf(stderr, ": %zu tree%s\n", missing.size(), missing.size() == 1 ? "" : "s");
    }
    for (size_t m : missing)
      std::fprintf(stderr, "    %s: %s\n", printable_text(forest.trees[report.missing[m]].id).c_str(),
                   printable_text(report.reasons[m]).c_str());
  }
  std::string failed;
  for (const auto& entry : by_task) failed += (failed.empty() ? "" : " ") + std::to_string(entry.first);
  // The rerun bakes what was submitted: the same output folder and the same --set.
  const std::string scene_word = shell_word(request.scene.string());
  const std::string rest = (request.out_dir.empty() ? "" : " -o " + shell_word(request.out_dir.string())) +
                           set_arguments(request.overrides) + " --resume";
  if (request.tasks > 0)
    std::fprintf(stderr, "what to do: %s, then run each failed task I again (it resumes), for I "
                         "in %s:\n  treeanim run %s --shard I/%zu%s\nand gather again.\n",
                 request.logs.empty() ? "read each tree's reason above" : "read the logs above",
                 failed.c_str(), printable_text(scene_word).c_str(), request.tasks, printable_text(rest).c_str());
  else
    std::fprintf(stderr, "what to do: bake the missing trees again (treeanim run %s%s bakes only those), then gather "
                         "again.\n",
                 printable_text(scene_word).c_str(), printable_text(rest).c_str());
  return kExitOutput;
}

}  // namespace treeanim
