// treeanim farm plan: a forest's farm tasks with their estimated cost (docs/farm.md).
#include <algorithm>
#include <cstdio>

#include "bake/forest_tasks.h"
#include "cli/commands.h"
#include "common/errors.h"
#include "common/message_text.h"
#include "files/free_space.h"
#include "files/text_output.h"

namespace treeanim {

int farm_plan_command(const FarmRequest& request) {
  const Scene scene = load_scene(request.scene, request.overrides);
  if (!request.json.empty()) check_text_output_target(request.json);  // after the scene noted its inputs
  if (!scene.forest)
    throw InputError(request.scene.string() + ": no /forest: farm plan splits a forest's trees into tasks");
  const Forest& forest = *scene.forest;
  const ForestEstimate estimate = estimate_forest(scene);
  const auto tasks = assign_tasks(estimate.tree_cost, request.tasks);
  const double hours_per_cost = kSecondsPerVertexStep / 3600.0;

  Json plan = {{"scene", request.scene.string()},
               {"trees", forest.trees.size()},
               {"tasks", Json::array()},
               {"seconds_per_vertex_step", kSecondsPerVertexStep}};
  std::printf("forest %s: %zu trees of %zu variants, %lld frames x %d substeps, %zu tasks\n",
              printable_text(request.scene.string()).c_str(), forest.trees.size(), forest.variants.size(), scene.time.frames,
              scene.time.substeps, tasks.size());
  std::printf("%6s %7s %14s %11s %10s\n", "task", "trees", "vertex-steps", "core-hours", "bytes");
  double total_cost = 0, total_bytes = 0, most = 0;
  for (size_t k = 0; k < tasks.size(); ++k) {
    double cost = 0, bytes = 0;
    Json ids = Json::array();
    for (size_t t : tasks[k]) {
      cost += double(estimate.tree_cost[t]);
      bytes += estimate.tree_bytes[t];
      ids.push_back(forest.trees[t].id);
    }
    total_cost += cost;
    total_bytes += bytes;
    most = std::max(most, cost);
    plan["tasks"].push_back({{"task", k},
                             {"trees", std::move(ids)},
                             {"vertex_steps", cost},
                             {"core_hours", cost * hours_per_cost},
                             {"bytes", bytes}});
    std::printf("%6zu %7zu %14.4g %11.4g %10s\n", k, tasks[k].size(), cost, cost * hours_per_cost,
                bytes_text(bytes).c_str());
  }
  const double mean = total_cost / double(tasks.size());
  plan["total"] = {{"vertex_steps", total_cost},
                   {"core_hours", total_cost * hours_per_cost},
                   {"bytes", total_bytes},
                   {"wall_hours", most * hours_per_cost},
                   {"imbalance", mean > 0 ? most / mean : 1.0}};
  std::printf("%6s %7zu %14.4g %11.4g %10s\n", "total", forest.trees.size(), total_cost, total_cost * hours_per_cost,
              bytes_text(total_bytes).c_str());
  std::printf("wall time with every task running at once: %.4g h (the costliest task, %.3f x the mean)\n",
              most * hours_per_cost, mean > 0 ? most / mean : 1.0);
  if (!request.json.empty()) write_text_output(request.json, plan.dump(2) + "\n");
  return 0;
}

}  // namespace treeanim
