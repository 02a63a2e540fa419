#include "bake/bake_plan.h"

#include <algorithm>

#include "output/output_formats.h"
#include "tree/surface_materials.h"

namespace treeanim {

BakePlan plan_frames(const Scene& scene, const BakeConfig& config) {
  BakePlan plan;
  plan.first = scene.time.start;
  plan.last = scene.time.start + scene.time.frames - 1;
  plan.written = config.frames.value_or(FrameRange{plan.first, plan.last});
  plan.frame_dt = 1.0 / scene.time.fps;
  plan.loop = scene.time.loop;
  // Only a bake of the whole loop closes it; --frames writes a part of it.
  plan.closes_loop = scene.time.loop && plan.written.first == plan.first && plan.written.last == plan.last;
  plan.use_checkpoints = config.checkpoints.resume || config.frames.has_value();
  plan.checkpoints = config.checkpoints;
  plan.reads_mesh = !scene.outputs.empty() || plan.written.first < last_checkpoint(plan) || plan.closes_loop;
  return plan;
}

BakePlan plan_bake(const Scene& scene, const BakeConfig& config) {
  BakePlan plan = plan_frames(scene, config);
  plan.key = {bake_key(scene, config.generator), config.generator, scene.hsm.precision == Precision::kFloat};
  return plan;
}

long long last_checkpoint(const BakePlan& plan) {
  const long long every = plan.checkpoints.every;
  if (every <= 0 || plan.written.last <= plan.first) return plan.first;
  return plan.first + (plan.written.last - plan.first) / every * every;
}

double frame_time(const BakePlan& plan, long long frame) { return static_cast<double>(frame) * plan.frame_dt; }

BakeInfo bake_info(const Scene& scene, const BakePlan& plan, const TreeModel& model, const TreePlacement* placement) {
  BakeInfo info;
  info.scene_json = scene.resolved.dump(2);
  info.generator = plan.key.generator;
  info.fps = scene.time.fps;
  info.frame_start = plan.written.first;
  info.frame_count = plan.written.count();
  info.substeps = scene.time.substeps;
  info.seed = scene.seed;
  info.loop = plan.closes_loop;
  info.loop_end_time = double(plan.last + 1) / scene.time.fps;
  info.materials = surface_materials(scene.tree);
  // Only outputs read the colours: a bake that writes none keeps no array of the mesh's size.
  if (!scene.outputs.empty())
    info.vertex_colors = leaf_color_factors(model, scene.tree.leaf_color_variation, scene.lsystem.seed);
  // Only the page plots the wind; a wind file's keys (up to some 10^7) are not copied for nothing.
  if (std::any_of(scene.outputs.begin(), scene.outputs.end(), [](const OutputOptions& o) { return std::string_view(o.format->name) == "html"; }))
    info.wind = scene.wind;
  if (placement) info.placement = *placement;
  return info;
}

}  // namespace treeanim
