#include "bake/bake_config.h"

#include "bake/scene_hash.h"
#include "treeanim_version.h"

namespace treeanim {

std::string treeanim_generator() { return std::string("treeanim ") + TREEANIM_VERSION; }

std::string bake_key(const Scene& scene, const std::string& generator) {
  return scene_hash(scene.resolved.dump(2), generator);
}

std::filesystem::path checkpoint_folder(const std::filesystem::path& out_dir, const std::filesystem::path& given) {
  return given.empty() ? out_dir / "checkpoints" : given;
}

BakeConfig tree_bake_config(const BakeConfig& forest, const std::string& id) {
  BakeConfig tree = forest;
  tree.checkpoints.dir = forest.checkpoints.dir / id;
  return tree;
}

}  // namespace treeanim
