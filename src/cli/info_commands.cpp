#include <cstdio>
#include <iostream>

#include "bake/bake_forest.h"
#include "bake/bake_plan.h"
#include "bake/forest_tasks.h"
#include "bake/prepare_tree.h"
#include "cli/commands.h"
#include "cli/progress.h"
#include "common/message_text.h"
#include "formats/output_estimate.h"
#include "formats/outputs.h"
#include "formats/sink_factories.h"
#include "output/output_formats.h"

namespace treeanim {

namespace {

void print_counts(const Json& summary) {
  std::printf("modules %lld after %d iterations; %lld segments, %lld leaves\n",
              summary["derivation"]["modules"].get<long long>(),
              summary["derivation"]["iterations"].get<int>(),
              summary["skeleton"]["segments"].get<long long>(),
              summary["skeleton"]["leaves"].get<long long>());
  std::printf("mesh %lld vertices, %lld triangles; %lld clusters, %lld memberships, %.3f kg\n",
              summary["mesh"]["vertices"].get<long long>(),
              summary["mesh"]["triangles"].get<long long>(),
              summary["model"]["clusters"].get<long long>(),
              summary["model"]["memberships"].get<long long>(),
              summary["model"]["mass_kg"].get<double>());
  if (summary["model"].contains("samples"))
    std::printf("simulated as %lld samples, %lld memberships (hsm.particles \"samples\")\n",
                summary["model"]["samples"].get<long long>(), summary["model"]["sample_memberships"].get<long long>());
}

// The checked volume (Scene::volume) => its figures, for `info --json`.
Json volume_json(const VolumeSummary& volume) {
  return {{"frames", {volume.first_frame, volume.last_frame}},
          {"layout", volume.layout},
          {"bounds_min", volume.active ? Json{volume.lower.x(), volume.lower.y(), volume.lower.z()} : Json()},
          {"bounds_max", volume.active ? Json{volume.upper.x(), volume.upper.y(), volume.upper.z()} : Json()},
          {"voxel_size", volume.voxel_size},
          {"largest_speed", volume.largest_speed}};
}

// The same as a line of text.
void print_volume(const VolumeSummary& volume) {
  char bounds[160] = "no active voxel (every point is outside it)";
  if (volume.active)
    std::snprintf(bounds, sizeof bounds, "bounds [%g %g %g] .. [%g %g %g] m", volume.lower.x(), volume.lower.y(),
                  volume.lower.z(), volume.upper.x(), volume.upper.y(), volume.upper.z());
  std::printf("wind volume: frames %lld to %lld, %s, %s, voxel %g m, largest speed %.3g m/s\n", volume.first_frame,
              volume.last_frame, volume.layout.c_str(), bounds, volume.voxel_size, volume.largest_speed);
}

// A long derivation says how far it is on stderr, as run's does (stdout is the command's own).
PreparedTree grown_tree(const Scene& scene) {
  LongTaskProgress growth(Verbosity::kNormal, stderr);
  return prepare_tree(scene, MeshSurface::kBuilt,
                      [&](int step, int steps, size_t modules) { growth.grown(step, steps, modules); });
}

// A forest's trees looked at as run looks at them before its first tree grows: every file has
// one writer, every variant in use grows, and every tree a seed shapes. A million trees take a
// minute, so each pass says how far it is, as run's do.
void check_forest(const Scene& scene) {
  LongTaskProgress progress(Verbosity::kNormal, stderr);
  const TreesPassed passed = [&](const char* what, size_t done, size_t total) { progress.trees(what, done, total); };
  check_forest_writers(scene, passed);
  shard_trees(scene, std::nullopt, passed);
}

// A lone tree's scene => its tree, grown, after what run refuses before it simulates: two
// outputs at one file, a folder or a device where one goes (the paths as run resolves them
// without -o), then each output's own limits.

PreparedTree prepare_checked_tree(const Scene& scene) {
  const BakePlan plan = plan_bake(scene, BakeConfig{});
  OutputTargets targets;
  targets.add_outputs(scene.outputs, {}, plan.written.first, plan.written.count());
  PreparedTree tree = grown_tree(scene);
  check_output_limits(scene.outputs, tree.model, bake_info(scene, plan, tree.model, nullptr));
  return tree;
}

}  // namespace

int validate_command(const std::filesystem::path& scene_file,
                     const std::vector<std::string>& overrides) {
  const Scene scene = load_scene(scene_file, overrides);
  if (scene.forest) {
    check_forest(scene);
    std::printf("forest of %zu trees, %zu variants\n", scene.forest->trees.size(), scene.forest->variants.size());
  } else {
    print_counts(tree_summary(scene, prepare_checked_tree(scene)));
  }
  if (scene.volume) print_volume(*scene.volume);
  std::printf("%s: OK\n", printable_text(scene_file.string()).c_str());
  return 0;
}

int info_command(const std::filesystem::path& scene_file, const std::vector<std::string>& overrides,
                 InfoFormat format) {
  const Scene scene = load_scene(scene_file, overrides);
  if (format == InfoFormat::kResolvedScene) {
    // The scene as a bake records it: every default filled in, overrides applied.
    std::cout << scene.resolved.dump(2) << "\n";
    return 0;
  }
  // A forest: the figures of its first tree. Outputs and trees that run would refuse are
  // refused here too (every variant in use grown, as validate does): figures of a bake that
  // cannot run would say it can.
  if (scene.forest) check_forest(scene);
  const Scene first = scene.forest ? tree_scene(scene, 0) : Scene();
  const Scene& one = scene.forest ? first : scene;
  const PreparedTree tree = scene.forest ? grown_tree(one) : prepare_checked_tree(one);
  Json summary = tree_summary(one, tree);
  if (scene.forest) {
    summary["forest"] = {{"trees", scene.forest->trees.size()},
                         {"variants", scene.forest->variants.size()},
                         {"tree", scene.forest->trees[0].id}};
    if (format == InfoFormat::kText)
      std::printf("forest of %zu trees, %zu variants; tree %s:\n", scene.forest->trees.size(),
                  scene.forest->variants.size(), scene.forest->trees[0].id.c_str());
  }
  Json& outputs = summary["estimate"]["outputs"] = Json::array();
  for (const OutputOptions& output : one.outputs)
    outputs.push_back({{"format", output.format->name},
                       {"path", output.path.string()},
                       {"bytes", estimated_output_bytes(output, tree.model.vertex_count(), tree.model.triangle_count(),
                                                        tree.model.cluster_count(), one.time.frames)}});
  if (scene.volume) summary["wind_volume"] = volume_json(*scene.volume);
  if (format == InfoFormat::kJson) {
    std::cout << summary.dump(2) << "\n";
    return 0;
  }
  print_counts(summary);
  const Json& box_min = summary["skeleton"]["bbox_min"];
  const Json& box_max = summary["skeleton"]["bbox_max"];
  std::printf("skeleton length %.4g, bbox [%g %g %g] .. [%g %g %g] (scene units)\n",
              summary["skeleton"]["total_length"].get<double>(), box_min[0].get<double>(),
              box_min[1].get<double>(), box_min[2].get<double>(), box_max[0].get<double>(),
              box_max[1].get<double>(), box_max[2].get<double>());
  std::printf("bake: %lld frames x %d substeps; %.1f KiB of positions per frame, %.1f MiB in all\n",
              scene.time.frames, scene.time.substeps,
              summary["estimate"]["bytes_per_frame"].get<double>() / 1024.0,
              summary["estimate"]["bytes_positions_total"].get<double>() / (1024.0 * 1024.0));
  for (const Json& output : outputs) {  // formats/output_estimate.h
    const std::string path = printable_text(output["path"].get<std::string>()), format = output["format"].get<std::string>();
    const double mib = output["bytes"].get<double>() / (1024.0 * 1024.0);
    if (find_planned_bytes(format))  // a format that plans its whole size before simulating
      std::printf("output %s (%s): at most %.1f MiB in all, planned to fit its limit\n", path.c_str(), format.c_str(), mib);
    else
      std::printf("output %s (%s): about %.1f MiB of frames, uncompressed\n", path.c_str(), format.c_str(), mib);
  }
  if (scene.volume) print_volume(*scene.volume);
  return 0;
}

}  // namespace treeanim
