// A forest's tree => the one-tree scene that bakes it (scene/scene.h).
#include "common/message_text.h"
#include "scene/scene.h"

namespace treeanim {

namespace {

Json tree_json(const ForestTree& tree, const ForestVariant& variant) {
  return Json{{"id", tree.id},
              {"variant", variant.name},
              {"seed", tree.seed},
              {"position", Json::array({tree.position.x(), tree.position.y(), tree.position.z()})},
              {"rotation", tree.rotation},
              {"scale", tree.scale}};
}

}  // namespace

Scene tree_scene(const Scene& forest_scene, size_t index) {
  const Forest& forest = *forest_scene.forest;
  const ForestTree& tree = forest.trees.at(index);
  const ForestVariant& variant = forest.variants.at(tree.variant);
  Scene scene;  // field by field: the forest's other trees stay behind
  scene.file = forest_scene.file;
  scene.seed = forest_scene.seed;
  scene.lsystem = variant.lsystem;
  scene.lsystem.seed = tree.seed;
  scene.tree = scaled_tree_options(variant.tree, tree.scale);
  scene.forest_tree = "forest tree '" + tree.id + "' (its scale " + number_text(tree.scale) + ")";
  scene.hsm = variant.hsm;
  scene.wind = forest_scene.wind;
  scene.time = forest_scene.time;
  scene.outputs = forest_scene.outputs;
  scene.input_paths = forest_scene.input_paths;  // the whole forest's: a changed grammar of one variant rebakes all
  scene.volume_frames = forest_scene.volume_frames;
  for (OutputOptions& output : scene.outputs) {
    std::string path = output.path.string();
    for (size_t at; (at = path.find(kTreePlaceholder)) != std::string::npos;)
      path.replace(at, std::string(kTreePlaceholder).size(), tree.id);
    output.path = path;
  }
  // Key by key, so a forest of 10,000 listed trees is not copied 10,000 times.
  scene.resolved = Json::object();
  for (const auto& [key, value] : forest_scene.resolved.items())
    scene.resolved[key] = key == "forest" ? Json{{"variants", Json::array({variant.resolved})},
                                                 {"trees", Json::array({tree_json(tree, variant)})}}
                                          : value;
  return scene;
}

}  // namespace treeanim
